# Third-party dependencies, all from Debian packages (scripts/install-deps.sh, README.md).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(OpenMP REQUIRED COMPONENTS CXX)

find_package(Protobuf REQUIRED)
pkg_check_modules(ZMQ REQUIRED IMPORTED_TARGET libzmq)
find_package(cppzmq QUIET)
if(NOT cppzmq_FOUND)
  find_path(CPPZMQ_INCLUDE_DIR zmq.hpp REQUIRED)
endif()
find_package(HDF5 REQUIRED COMPONENTS C)
find_package(yaml-cpp REQUIRED)
find_package(spdlog REQUIRED)
find_package(CLI11 REQUIRED)
find_package(GTest REQUIRED)
find_package(benchmark QUIET)
find_package(SQLite3 QUIET)

# HDF5 as one imported target, whatever FindHDF5 provides on this CMake.
if(NOT TARGET coredem::hdf5)
  add_library(coredem::hdf5 INTERFACE IMPORTED)
  if(TARGET hdf5::hdf5)
    target_link_libraries(coredem::hdf5 INTERFACE hdf5::hdf5)
  else()
    target_include_directories(coredem::hdf5 INTERFACE ${HDF5_INCLUDE_DIRS})
    target_link_libraries(coredem::hdf5 INTERFACE ${HDF5_C_LIBRARIES})
    target_compile_definitions(coredem::hdf5 INTERFACE ${HDF5_DEFINITIONS})
  endif()
endif()

# ZeroMQ (C library + cppzmq header-only binding) as one target. PRIVATE link only:
# ZeroMQ never appears in a public header (pimpl).
if(NOT TARGET coredem::zmq)
  add_library(coredem::zmq INTERFACE IMPORTED)
  target_link_libraries(coredem::zmq INTERFACE PkgConfig::ZMQ)
  if(CPPZMQ_INCLUDE_DIR)
    target_include_directories(coredem::zmq INTERFACE ${CPPZMQ_INCLUDE_DIR})
  endif()
endif()

# Python for plot scripts and test helpers: the interpreter that has Debian's python3
# packages (matplotlib, h5py, zmq, protobuf), not whichever python3 is first on PATH.
set(COREDEM_PYTHON "" CACHE FILEPATH "Python interpreter with matplotlib, h5py, numpy")
if(NOT COREDEM_PYTHON)
  foreach(cand /usr/bin/python3 python3)
    find_program(_py NAMES ${cand} NO_CACHE)
    if(_py)
      execute_process(COMMAND ${_py} -c "import matplotlib, h5py, numpy"
                      RESULT_VARIABLE _rc OUTPUT_QUIET ERROR_QUIET)
      if(_rc EQUAL 0)
        set(COREDEM_PYTHON ${_py} CACHE FILEPATH "Python interpreter with matplotlib, h5py, numpy" FORCE)
        break()
      endif()
    endif()
    unset(_py)
  endforeach()
endif()
if(NOT COREDEM_PYTHON)
  message(WARNING "No python3 with matplotlib, h5py and numpy found: plots and Python-based "
                  "tests are disabled. Run scripts/install-deps.sh.")
endif()

# ParaView's pvbatch for `coredem render` and the ParaView e2e test (optional: Debian's paraview;
# without a display it runs on a private Xvfb, Debian's xvfb, started by
# scripts/render/with-xvfb.sh). Looked up again on PATH at run time.
find_program(COREDEM_PVBATCH pvbatch DOC "ParaView's pvbatch (coredem render)")
if(NOT COREDEM_PVBATCH)
  message(STATUS "pvbatch not found: coredem render and the ParaView e2e tests need Debian's "
                 "paraview and xvfb (scripts/install-deps.sh)")
  set(COREDEM_PVBATCH "")
endif()

include(CoredemWarnings)   # coredem_warnings, COREDEM_ENABLE_ASSERTS
