# GoogleTest: catkin's (a ROS build with CATKIN_ENABLE_TESTING defines GTest::gtest_main), an
# installed package, else built from sources (a bare GPU machine has none: carry
# /usr/src/googletest there and point CVO_GTEST_SOURCE_DIR at it). Without any of them a ROS build
# goes on without its tests (CVO_BUILD_TESTS OFF, with a warning); a ROS-free build stops.
if(NOT TARGET GTest::gtest_main)
  find_package(GTest QUIET)
endif()
if(NOT TARGET GTest::gtest_main)
  if(EXISTS "${CVO_GTEST_SOURCE_DIR}/CMakeLists.txt")
    set(INSTALL_GTEST OFF CACHE BOOL "" FORCE)
    set(BUILD_GMOCK OFF CACHE BOOL "" FORCE)
    # Never taken in a catkin build where GoogleTest exists (catkin defines GTest::gtest_main
    # from the same sources): ROS-free builds on machines without libgtest-dev.
    #catkin_lint: ignore_once external_subdir
    add_subdirectory(${CVO_GTEST_SOURCE_DIR} ${CMAKE_BINARY_DIR}/googletest EXCLUDE_FROM_ALL)
    if(NOT TARGET GTest::gtest_main)  # googletest 1.11 and later define it themselves
      add_library(GTest::gtest_main ALIAS gtest_main)
    endif()
  elseif(CVO_WITH_ROS)
    message(WARNING "cvo_odometry: GoogleTest not found (apt install libgtest-dev): no tests")
    set(CVO_BUILD_TESTS OFF)
  else()
    message(FATAL_ERROR "GoogleTest not found: install libgtest-dev or set CVO_GTEST_SOURCE_DIR")
  endif()
endif()

if(CVO_BUILD_TESTS)
  include(GoogleTest)

  # cvo_add_gtest(name source... LIBS lib...)
  function(cvo_add_gtest name)
    cmake_parse_arguments(ARG "" "" "LIBS" ${ARGN})
    add_executable(${name} ${ARG_UNPARSED_ARGUMENTS})
    target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest_main)
    target_compile_definitions(${name} PRIVATE CVO_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/test/data")
    # Limits a slow or loaded machine cannot reach (listing takes about a second under ASan; the
    # slowest test case about a minute): only a hang does.
    gtest_discover_tests(${name} DISCOVERY_TIMEOUT 300 PROPERTIES TIMEOUT 900)
    add_dependencies(tests ${name})
  endfunction()

  if(NOT TARGET tests)
    add_custom_target(tests)
  endif()
endif()
