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
    # No GPU to detect at build time: Turing, Ampere desktop, Jetson Orin, Ada, Hopper
    # (H100/H200, also as PTX for newer chips) and Blackwell desktop.
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      set(CMAKE_CUDA_ARCHITECTURES "75-real;86-real;87-real;89-real;90;120-real")
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
