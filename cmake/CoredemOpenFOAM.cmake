# OpenFOAM participant: resolves COREDEM_OPENFOAM (AUTO|ON|OFF) into COREDEM_OPENFOAM_ENABLED.
#
# Debian's `openfoam` package ships the libraries (/usr/lib) and the etc tree
# (/usr/share/openfoam/etc) but no headers; scripts/openfoam-headers.sh fetches Debian's source
# package of the installed version and prepares the lnInclude trees in
# ${PROJECT_BINARY_DIR}/_deps/openfoam-<version> (once; a stamp file makes later configures
# skip it). See docs/openfoam.md.
#
# Provides, when enabled:
#   coredem::openfoam           INTERFACE imported target: OpenFOAM core include dirs, the
#                               compile definitions/flags Debian built the libraries with, and
#                               libfiniteVolume, libmeshTools, libOpenFOAM, dl, m
#   coredem_add_openfoam_application(NAME SOURCES ... [LIBS ...] [INCLUDES ...])
#                               an OpenFOAM application in build/bin, compiled with OpenFOAM's
#                               own C++ standard (COREDEM_OPENFOAM_CXX_STANDARD)
#   COREDEM_OPENFOAM_HEADERS    the prepared tree (openfoam-headers.stamp, src/, wmake/)
#   COREDEM_OPENFOAM_SRC        the prepared source tree's src/ (like wmake's $(LIB_SRC))
#   COREDEM_OPENFOAM_PROJECT_DIR  the WM_PROJECT_DIR applications need at run time
#   COREDEM_OPENFOAM_API        e.g. 1912
#   COREDEM_OPENFOAM_BIN_DIR    where Debian's utilities (blockMesh, ...) are

set(COREDEM_OPENFOAM_ENABLED OFF)
set(COREDEM_OPENFOAM_CXX_STANDARD 14 CACHE STRING
    "C++ standard of OpenFOAM translation units (OpenFOAM v1912 is written for C++11/14)")
set(COREDEM_OPENFOAM_LIBDIR /usr/lib CACHE PATH "Where Debian's OpenFOAM libraries are")
set(COREDEM_OPENFOAM_PROJECT_DIR /usr/share/openfoam CACHE PATH
    "OpenFOAM project dir with the etc/ tree (WM_PROJECT_DIR at run time)")
set(COREDEM_OPENFOAM_HEADERS_DIR "" CACHE PATH
    "Prepared OpenFOAM headers (default: <build>/_deps/openfoam-<version>); may be shared")
set(_coredem_openfoam_script ${PROJECT_SOURCE_DIR}/scripts/openfoam-headers.sh)
set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
             ${_coredem_openfoam_script})

# Include directories (relative to src/) of the OpenFOAM libraries an application may name in
# LIBS; the trees are prepared by scripts/openfoam-headers.sh (keep both lists in step).
set(_coredem_openfoam_core_includes
    finiteVolume/lnInclude meshTools/lnInclude OpenFOAM/lnInclude OSspecific/POSIX/lnInclude)
set(_coredem_openfoam_inc_fvOptions fvOptions/lnInclude)
set(_coredem_openfoam_inc_sampling sampling/lnInclude)
set(_coredem_openfoam_inc_incompressibleTransportModels
    transportModels transportModels/incompressible/lnInclude
    transportModels/incompressible/singlePhaseTransportModel)
set(_coredem_openfoam_inc_turbulenceModels TurbulenceModels/turbulenceModels/lnInclude)
set(_coredem_openfoam_inc_incompressibleTurbulenceModels
    TurbulenceModels/turbulenceModels/lnInclude TurbulenceModels/incompressible/lnInclude)
set(_coredem_openfoam_inc_DPMTurbulenceModels
    TurbulenceModels/turbulenceModels/lnInclude TurbulenceModels/incompressible/lnInclude
    TurbulenceModels/phaseIncompressible/lnInclude)
# The thermophysical libraries of coredemFoam's variable-density gas (rhoReactionThermo).
set(_coredem_openfoam_inc_specie thermophysicalModels/specie/lnInclude)
set(_coredem_openfoam_inc_fluidThermophysicalModels
    thermophysicalModels/specie/lnInclude thermophysicalModels/basic/lnInclude
    transportModels/compressible/lnInclude)
set(_coredem_openfoam_inc_reactionThermophysicalModels
    thermophysicalModels/specie/lnInclude thermophysicalModels/basic/lnInclude
    transportModels/compressible/lnInclude thermophysicalModels/reactionThermo/lnInclude)

# Ends _coredem_openfoam_resolve with <out_why> = the concatenated message.
macro(_coredem_openfoam_fail)
  string(CONCAT _coredem_openfoam_msg ${ARGN})
  set(${out_why} "${_coredem_openfoam_msg}" PARENT_SCOPE)
  return()
endmacro()

# Sets <out_ok> TRUE and defines the target when everything is there; otherwise <out_why>
# says what is missing and what to do.
function(_coredem_openfoam_resolve out_ok out_why)
  set(${out_ok} FALSE PARENT_SCOPE)
  find_program(_dpkg_query dpkg-query NO_CACHE)
  if(NOT _dpkg_query)
    _coredem_openfoam_fail("dpkg-query not found: the OpenFOAM participant needs Debian's openfoam package")
  endif()
  execute_process(COMMAND ${_dpkg_query} -W "-f=\${Status}|\${Version}|\${source:Version}" openfoam
                  OUTPUT_VARIABLE _q RESULT_VARIABLE _rc ERROR_QUIET)
  if(NOT _rc EQUAL 0 OR NOT _q MATCHES "install ok installed")
    _coredem_openfoam_fail("Debian's openfoam package is not installed (scripts/install-deps.sh installs it)")
  endif()
  string(REPLACE "|" ";" _q "${_q}")
  list(GET _q 1 _bin_version)
  list(GET _q 2 _src_version)
  string(REGEX MATCH "^[0-9]+" _api "${_src_version}")

  foreach(lib OpenFOAM finiteVolume meshTools)
    find_library(COREDEM_OPENFOAM_LIB_${lib} NAMES ${lib} PATHS ${COREDEM_OPENFOAM_LIBDIR}
                 NO_DEFAULT_PATH)
    if(NOT COREDEM_OPENFOAM_LIB_${lib})
      _coredem_openfoam_fail("lib${lib}.so not found in ${COREDEM_OPENFOAM_LIBDIR} although openfoam "
                     "${_bin_version} is installed (apt-get install --reinstall libopenfoam)")
    endif()
  endforeach()
  if(NOT EXISTS ${COREDEM_OPENFOAM_PROJECT_DIR}/etc/controlDict)
    _coredem_openfoam_fail("${COREDEM_OPENFOAM_PROJECT_DIR}/etc/controlDict is missing: OpenFOAM "
                   "applications cannot run without the etc tree (set COREDEM_OPENFOAM_PROJECT_DIR)")
  endif()
  find_program(COREDEM_OPENFOAM_BLOCKMESH blockMesh PATHS /usr/bin)
  if(NOT COREDEM_OPENFOAM_BLOCKMESH)
    _coredem_openfoam_fail("blockMesh not found although openfoam ${_bin_version} is installed "
                           "(cases are meshed with it; apt-get install --reinstall openfoam)")
  endif()
  get_filename_component(_bin_dir ${COREDEM_OPENFOAM_BLOCKMESH} DIRECTORY)

  set(_dir "${COREDEM_OPENFOAM_HEADERS_DIR}")
  if(NOT _dir)
    set(_dir ${PROJECT_BINARY_DIR}/_deps/openfoam-${_src_version})
  endif()
  set(_stamp ${_dir}/openfoam-headers.stamp)
  set(_fresh FALSE)
  if(EXISTS ${_stamp} AND ${_stamp} IS_NEWER_THAN ${_coredem_openfoam_script})
    file(STRINGS ${_stamp} _stamp_version REGEX "^version=")
    if(_stamp_version STREQUAL "version=${_src_version}")
      set(_fresh TRUE)
    endif()
  endif()
  if(_fresh)
    message(STATUS "OpenFOAM ${_src_version} headers: ${_dir} (stamp present)")
  else()
    message(STATUS "OpenFOAM ${_src_version} headers: scripts/openfoam-headers.sh ${_dir} "
                   "(the first time downloads ~45 MB and takes under a minute)")
    execute_process(COMMAND bash ${_coredem_openfoam_script} ${_dir}
                    RESULT_VARIABLE _rc TIMEOUT 1800)
    if(NOT _rc EQUAL 0)
      _coredem_openfoam_fail("scripts/openfoam-headers.sh ${_dir} failed (exit ${_rc}, see its message "
                     "above)")
    endif()
  endif()

  set(_src ${_dir}/src)
  set(_incs)
  foreach(inc ${_coredem_openfoam_core_includes})
    if(NOT IS_DIRECTORY ${_src}/${inc})
      _coredem_openfoam_fail("${_src}/${inc} is missing; delete ${_stamp} and configure again")
    endif()
    list(APPEND _incs ${_src}/${inc})
  endforeach()

  if(NOT TARGET coredem::openfoam)
    add_library(coredem::openfoam INTERFACE IMPORTED GLOBAL)
    # Imported targets' include directories are SYSTEM: OpenFOAM's headers do not trip our
    # warnings. Definitions and flags are Debian's build of the libraries (debian/rules:
    # linux64 Gcc, double precision, 32-bit labels) and OpenFOAM's wmake rules.
    set_target_properties(coredem::openfoam PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${_incs}"
      INTERFACE_COMPILE_DEFINITIONS "OPENFOAM=${_api};WM_DP;WM_LABEL_SIZE=32;NoRepository"
      INTERFACE_COMPILE_OPTIONS "-pthread;-ftemplate-depth-100"
      # OpenFOAM registers run-time selectable models from static initialisers: every named
      # library must stay linked even if no symbol of it is referenced.
      INTERFACE_LINK_OPTIONS "-pthread;LINKER:--add-needed;LINKER:--no-as-needed"
      INTERFACE_LINK_LIBRARIES
        "${COREDEM_OPENFOAM_LIB_finiteVolume};${COREDEM_OPENFOAM_LIB_meshTools};${COREDEM_OPENFOAM_LIB_OpenFOAM};dl;m")
  endif()

  set(COREDEM_OPENFOAM_SRC ${_src} CACHE INTERNAL "OpenFOAM src/ with lnInclude trees")
  set(COREDEM_OPENFOAM_HEADERS ${_dir} CACHE INTERNAL "Prepared OpenFOAM tree (stamp, src/, wmake/)")
  set(COREDEM_OPENFOAM_API ${_api} CACHE INTERNAL "OpenFOAM API number")
  set(COREDEM_OPENFOAM_VERSION ${_bin_version} CACHE INTERNAL "Installed openfoam package version")
  set(COREDEM_OPENFOAM_BIN_DIR "${_bin_dir}" CACHE INTERNAL "Debian's OpenFOAM utilities")
  set(${out_ok} TRUE PARENT_SCOPE)
endfunction()

if(NOT COREDEM_OPENFOAM STREQUAL "OFF")
  _coredem_openfoam_resolve(_coredem_openfoam_ok _coredem_openfoam_why)
  if(_coredem_openfoam_ok)
    set(COREDEM_OPENFOAM_ENABLED ON)
    message(STATUS "OpenFOAM participant: Debian openfoam ${COREDEM_OPENFOAM_VERSION} "
                   "(API ${COREDEM_OPENFOAM_API}), headers in ${COREDEM_OPENFOAM_SRC}")
  elseif(COREDEM_OPENFOAM STREQUAL "ON")
    message(FATAL_ERROR "COREDEM_OPENFOAM=ON but the OpenFOAM participant cannot be built: "
                        "${_coredem_openfoam_why}. Fix that, or configure with "
                        "-DCOREDEM_OPENFOAM=AUTO (skip it when unavailable) or OFF.")
  else()
    message(WARNING "OpenFOAM participant disabled (COREDEM_OPENFOAM=AUTO): "
                    "${_coredem_openfoam_why}. Its tests are not built and `make test` fails "
                    "(coverage.openfoam.missing): fix it and configure again, or configure with "
                    "-DCOREDEM_OPENFOAM=OFF to leave the OpenFOAM participant and its tests out.")
  endif()
endif()

# coredem_add_openfoam_application(NAME name SOURCES ... [LIBS ...] [INCLUDES ...])
#   LIBS      OpenFOAM libraries by their wmake name (as in Make/options EXE_LIBS without -l),
#             found in COREDEM_OPENFOAM_LIBDIR; the known ones (fvOptions, sampling,
#             incompressibleTransportModels, turbulenceModels, incompressibleTurbulenceModels,
#             DPMTurbulenceModels, specie, fluidThermophysicalModels,
#             reactionThermophysicalModels) bring their include directories along.
#   INCLUDES  extra include directories (relative ones are taken relative to the current
#             source dir; use ${COREDEM_OPENFOAM_SRC}/... for other OpenFOAM trees).
# The application's own directory is on the include path (createFields.H, UEqn.H, ...).
function(coredem_add_openfoam_application)
  cmake_parse_arguments(A "" "NAME" "SOURCES;LIBS;INCLUDES" ${ARGN})
  if(NOT COREDEM_OPENFOAM_ENABLED)
    message(FATAL_ERROR "coredem_add_openfoam_application(${A_NAME}) called although "
                        "COREDEM_OPENFOAM_ENABLED is OFF; guard it with if(COREDEM_OPENFOAM_ENABLED)")
  endif()
  if(NOT A_NAME OR NOT A_SOURCES)
    message(FATAL_ERROR "coredem_add_openfoam_application needs NAME and SOURCES")
  endif()
  set(_libs)
  set(_incs)
  foreach(lib ${A_LIBS})
    find_library(COREDEM_OPENFOAM_LIB_${lib} NAMES ${lib} PATHS ${COREDEM_OPENFOAM_LIBDIR}
                 NO_DEFAULT_PATH)
    if(NOT COREDEM_OPENFOAM_LIB_${lib})
      message(FATAL_ERROR "${A_NAME}: OpenFOAM library lib${lib}.so is not in "
                          "${COREDEM_OPENFOAM_LIBDIR}; Debian's libopenfoam does not ship it")
    endif()
    list(APPEND _libs ${COREDEM_OPENFOAM_LIB_${lib}})
    foreach(inc ${_coredem_openfoam_inc_${lib}})
      if(NOT IS_DIRECTORY ${COREDEM_OPENFOAM_SRC}/${inc})
        message(FATAL_ERROR "${A_NAME}: ${COREDEM_OPENFOAM_SRC}/${inc} is missing; add it to "
                            "scripts/openfoam-headers.sh and configure again")
      endif()
      list(APPEND _incs ${COREDEM_OPENFOAM_SRC}/${inc})
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES _incs)

  add_executable(${A_NAME} ${A_SOURCES})
  # OpenFOAM's headers are written for C++11/14 (not C++20-clean): these translation units
  # keep OpenFOAM's own standard, separate from the project's C++20.
  set_target_properties(${A_NAME} PROPERTIES
    CXX_STANDARD ${COREDEM_OPENFOAM_CXX_STANDARD}
    CXX_STANDARD_REQUIRED ON
    CXX_EXTENSIONS OFF
    RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
  target_include_directories(${A_NAME} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR} ${A_INCLUDES})
  target_include_directories(${A_NAME} SYSTEM PRIVATE ${_incs})
  # OpenFOAM's own warning set (wmake rules General/Gcc/c++), minus -Wold-style-cast which
  # its macros trip.
  target_compile_options(${A_NAME} PRIVATE -Wall -Wextra -Wnon-virtual-dtor
                         -Wno-unused-parameter -Wno-invalid-offsetof -Wno-attributes
                         -Wno-unknown-pragmas)
  target_link_libraries(${A_NAME} PRIVATE ${_libs} coredem::openfoam)
endfunction()
