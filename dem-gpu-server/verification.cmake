# Analytic and reference solutions of the thermochemistry verification suite (docs/physics.md §8):
# header-only, include/coredem/dem/verification/analytic.h. Link coredem::dem_verification to
# compare a simulation against them (e.g. `coredem verify`). Included from
# dem-gpu-server/CMakeLists.txt after coredem_dem_kernels is defined:
#   include(${CMAKE_CURRENT_SOURCE_DIR}/verification.cmake)
if(NOT TARGET coredem_dem_verification)
  add_library(coredem_dem_verification INTERFACE)
  add_library(coredem::dem_verification ALIAS coredem_dem_verification)
  target_include_directories(coredem_dem_verification INTERFACE ${CMAKE_CURRENT_LIST_DIR}/include)
  # analytic.h uses the DEM_HD kernels and COREDEM_CHECK (coredem/common/check.h).
  target_link_libraries(coredem_dem_verification INTERFACE coredem::dem_kernels coredem::common)
  target_compile_features(coredem_dem_verification INTERFACE cxx_std_20)
endif()
