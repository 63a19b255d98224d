# The tests in a ROS build (test/ is EXCLUDE_FROM_ALL there, as in every catkin package).
#
# `tests` also builds what the tests run (the tools, the nodelet, the Python messages), so that
# `catkin_make run_tests` works before or without `catkin_make`.
foreach(dir src/core src/frontend src/tools src/ros bench)
  get_property(CVO_DIR_TARGETS DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  if(CVO_DIR_TARGETS)
    add_dependencies(tests ${CVO_DIR_TARGETS})
  endif()
endforeach()
add_dependencies(tests ${PROJECT_NAME}_generate_messages ${PROJECT_NAME}_gencfg)

# `catkin_make run_tests` (and catkin-tools' `catkin test`) builds the tests and runs this
# package's ctest suite (unit tests, the tools' checks, the rostests), with a JUnit file in the
# workspace's test_results/cvo_odometry/ for catkin_test_results. It fails when a test fails.
# ctest in the package's build folder (or `catkin_make test` after `catkin_make tests`) runs the
# same suite.
if(TARGET run_tests)
  cmake_host_system_information(RESULT CVO_TEST_JOBS QUERY NUMBER_OF_LOGICAL_CORES)
  set(CVO_CTEST ${CMAKE_CTEST_COMMAND} --output-on-failure -j${CVO_TEST_JOBS})
  if(NOT CMAKE_VERSION VERSION_LESS 3.21)  # ctest --output-junit
    set(CVO_JUNIT ${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/ctest-${PROJECT_NAME}.xml)
    set(CVO_CTEST ${PYTHON_EXECUTABLE} ${PROJECT_SOURCE_DIR}/cmake/cvo_ctest_junit.py ${CVO_JUNIT}
                  ${CVO_CTEST} --output-junit ${CVO_JUNIT})
  endif()
  add_custom_target(run_tests_${PROJECT_NAME}_ctest
    COMMAND ${CMAKE_COMMAND} -E make_directory ${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}
    COMMAND ${CVO_CTEST}
    WORKING_DIRECTORY ${PROJECT_BINARY_DIR} USES_TERMINAL VERBATIM)
  add_dependencies(run_tests_${PROJECT_NAME}_ctest tests)
  add_dependencies(run_tests run_tests_${PROJECT_NAME}_ctest)
endif()
