# Decides CVO_CUDA_ENABLED from CVO_WITH_CUDA and enables the CUDA language.
include(CheckLanguage)
set(CVO_CUDA_ENABLED OFF)
if(NOT CVO_WITH_CUDA STREQUAL "OFF")
  # CMake only finds nvcc through PATH or CUDACXX; try the standard install location too.
  if(NOT DEFINED ENV{CUDACXX} AND NOT CMAKE_CUDA_COMPILER AND EXISTS /usr/local/cuda/bin/nvcc)
    set(CMAKE_CUDA_COMPILER /usr/local/cuda/bin/nvcc)
  endif()
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    # The architectures: CMAKE_CUDA_ARCHITECTURES when given; else the GPUs nvidia-smi lists
    # (each architecture's code once: a quick build for this machine), else Turing's code and
    # its PTX, which the driver of a newer GPU compiles once at the program's first start and
    # caches. CI builds all that the users have (CVO_CUDA_ARCHITECTURES=all in scripts/env.sh:
    # "75-real;86-real;87-real;89-real;90;120-real": Turing, Ampere desktop, Jetson Orin, Ada,
    # Hopper H100/H200 also as PTX for newer chips, Blackwell desktop).
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      set(archs "")
      find_program(CVO_NVIDIA_SMI nvidia-smi)
      if(CVO_NVIDIA_SMI)
        execute_process(COMMAND ${CVO_NVIDIA_SMI} --query-gpu=compute_cap --format=csv,noheader
                        OUTPUT_VARIABLE caps RESULT_VARIABLE rc ERROR_QUIET TIMEOUT 30)
        if(rc EQUAL 0)
          string(REGEX MATCHALL "[0-9]+\\.[0-9]+" caps "${caps}")
          foreach(cap ${caps})
            string(REPLACE "." "" arch "${cap}")
            list(APPEND archs ${arch})
          endforeach()
          list(REMOVE_DUPLICATES archs)
        endif()
      endif()
      if(archs)
        message(STATUS "cvo_odometry: CUDA code for this machine's GPUs (nvidia-smi): ${archs}")
      else()
        set(archs 75)
        message(STATUS "cvo_odometry: no GPU listed by nvidia-smi: CUDA code for Turing (75) "
                       "and its PTX, which a newer GPU's driver compiles at the first start (can "
                       "take minutes, then cached). Building for another machine (Docker, a "
                       "Jetson)? Set CMAKE_CUDA_ARCHITECTURES to its GPU's: 86, 87 (Jetson "
                       "Orin), 89, 90, 120, or the list CI builds: "
                       "\"75-real;86-real;87-real;89-real;90;120-real\"")
      endif()
      set(CMAKE_CUDA_ARCHITECTURES "${archs}" CACHE STRING
          "CUDA architectures (default: the GPUs nvidia-smi lists, else 75)")
    endif()
    enable_language(CUDA)
    find_package(CUDAToolkit REQUIRED)
    set(CMAKE_CUDA_STANDARD 17)
    set(CMAKE_CUDA_STANDARD_REQUIRED ON)
    set(CVO_CUDA_ENABLED ON)
  elseif(CVO_WITH_CUDA STREQUAL "ON")
    message(FATAL_ERROR "CVO_WITH_CUDA=ON but no CUDA compiler was found")
  endif()
endif()
