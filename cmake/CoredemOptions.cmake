# Tri-state options: AUTO enables a part when its toolchain is found, ON requires it,
# OFF skips it. The resolved values are COREDEM_CUDA_ENABLED / COREDEM_OPENFOAM_ENABLED.

set(COREDEM_CUDA AUTO CACHE STRING "Build the CUDA DEM backend (AUTO|ON|OFF)")
set_property(CACHE COREDEM_CUDA PROPERTY STRINGS AUTO ON OFF)
set(COREDEM_OPENFOAM AUTO CACHE STRING "Build the OpenFOAM participant (AUTO|ON|OFF)")
set_property(CACHE COREDEM_OPENFOAM PROPERTY STRINGS AUTO ON OFF)
set(COREDEM_CUDA_ARCHITECTURES "75-real;80-real;90" CACHE STRING
    "CUDA architectures of the CUDA backend (CMAKE_CUDA_ARCHITECTURES syntax; `native` = this machine's GPUs)")
option(COREDEM_ENABLE_ASSERTS "Keep internal COREDEM_ASSERT checks in release builds" OFF)

foreach(opt COREDEM_CUDA COREDEM_OPENFOAM)
  if(NOT ${opt} MATCHES "^(AUTO|ON|OFF)$")
    message(FATAL_ERROR "${opt}=${${opt}} is not allowed; use AUTO, ON or OFF.")
  endif()
endforeach()

# --- CUDA ------------------------------------------------------------------------------
set(COREDEM_CUDA_ENABLED OFF)
if(NOT COREDEM_CUDA STREQUAL "OFF")
  include(CheckLanguage)
  if(NOT CMAKE_CUDA_COMPILER)
    # nvcc is often installed outside PATH; look in the usual toolkit location too.
    find_program(_coredem_nvcc nvcc HINTS ENV CUDAToolkit_ROOT PATH_SUFFIXES bin
                 PATHS /usr/local/cuda/bin)
    if(_coredem_nvcc)
      set(CMAKE_CUDA_COMPILER ${_coredem_nvcc} CACHE FILEPATH "CUDA compiler")
    endif()
  endif()
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    # The GPUs the CUDA backend is compiled for: machine code (SASS) for Turing (75), Ampere
    # (80, also runs on 86/87/89) and Hopper (90), plus PTX of 90 that the driver compiles for
    # anything newer (Blackwell). `native`: only the GPUs of the build machine. A value given
    # as CMAKE_CUDA_ARCHITECTURES on the command line takes precedence.
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      set(CMAKE_CUDA_ARCHITECTURES ${COREDEM_CUDA_ARCHITECTURES})
    endif()
    enable_language(CUDA)
    set(CMAKE_CUDA_STANDARD 20)
    set(CMAKE_CUDA_STANDARD_REQUIRED ON)
    find_package(CUDAToolkit REQUIRED)
    set(COREDEM_CUDA_ENABLED ON)
    message(STATUS "CoReDEM: CUDA architectures ${CMAKE_CUDA_ARCHITECTURES} "
                   "(COREDEM_CUDA_ARCHITECTURES)")
  elseif(COREDEM_CUDA STREQUAL "ON")
    message(FATAL_ERROR "COREDEM_CUDA=ON but no CUDA compiler (nvcc) was found. Put nvcc on "
                        "PATH or set CUDAToolkit_ROOT, or configure with -DCOREDEM_CUDA=OFF.")
  endif()
endif()

# --- OpenFOAM (resolved in cmake/CoredemOpenFOAM.cmake) ----------------------------------
if(COREDEM_CORE_ONLY)
  set(COREDEM_OPENFOAM_ENABLED OFF)
else()
  include(CoredemOpenFOAM)
endif()
