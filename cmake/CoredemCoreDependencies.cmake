# Dependencies of the DEM core built alone (COREDEM_CORE_ONLY): the compiler's OpenMP and the
# threads library, nothing else. CUDA is resolved in CoredemOptions.cmake.
#
# Tests use GoogleTest: the installed package when there is one, else a GoogleTest source tree
# (COREDEM_GTEST_SOURCE_DIR: Debian's googletest package ships it in /usr/src/googletest; on a
# machine where nothing can be installed, a copy carried there). Without either the core builds
# without its tests (COREDEM_CORE_TESTS=OFF).
find_package(Threads REQUIRED)
find_package(OpenMP REQUIRED COMPONENTS CXX)

set(COREDEM_GTEST_SOURCE_DIR "" CACHE PATH
    "GoogleTest source tree (with googletest/ and googlemock/) used when no GTest package is found")
set(COREDEM_CORE_TESTS OFF)
find_package(GTest QUIET)
if(GTest_FOUND)
  set(COREDEM_CORE_TESTS ON)
  message(STATUS "CoReDEM core: GoogleTest package found")
else()
  set(_gtest_src "${COREDEM_GTEST_SOURCE_DIR}")
  if(NOT _gtest_src AND EXISTS /usr/src/googletest/CMakeLists.txt)
    set(_gtest_src /usr/src/googletest)
  endif()
  if(_gtest_src AND EXISTS "${_gtest_src}/CMakeLists.txt")
    set(INSTALL_GTEST OFF CACHE BOOL "" FORCE)
    set(BUILD_GMOCK OFF CACHE BOOL "" FORCE)
    add_subdirectory("${_gtest_src}" ${PROJECT_BINARY_DIR}/_deps/googletest EXCLUDE_FROM_ALL)
    foreach(_t gtest gtest_main) # GoogleTest ≥ 1.11 names its own aliases
      if(NOT TARGET GTest::${_t})
        add_library(GTest::${_t} ALIAS ${_t})
      endif()
    endforeach()
    set(COREDEM_CORE_TESTS ON)
    message(STATUS "CoReDEM core: GoogleTest built from ${_gtest_src}")
  elseif(_gtest_src)
    message(FATAL_ERROR "COREDEM_GTEST_SOURCE_DIR=${_gtest_src} holds no CMakeLists.txt: point it "
                        "at a GoogleTest source tree (Debian: /usr/src/googletest).")
  else()
    message(WARNING "CoReDEM core: no GoogleTest package and no source tree "
                    "(COREDEM_GTEST_SOURCE_DIR): the conformance tests are not built.")
  endif()
endif()

include(CoredemWarnings)   # coredem_warnings, COREDEM_ENABLE_ASSERTS
