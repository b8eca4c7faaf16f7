# coredem-bench thermochem: the DEM core with heat transfer, and the chemistry kernel loops
# (OpenMP here; CUDA kernels in thermochem.cu when the CUDA backend is built).
target_link_libraries(coredem-bench PRIVATE coredem::dem OpenMP::OpenMP_CXX)
if(COREDEM_CUDA_ENABLED)
  target_sources(coredem-bench PRIVATE ${CMAKE_CURRENT_LIST_DIR}/thermochem.cu)
  target_compile_definitions(coredem-bench PRIVATE COREDEM_BENCH_CUDA=1)
  # The kernel headers need only C++17; CMake 3.25 does not know nvcc 13's C++20 flag.
  set_target_properties(coredem-bench PROPERTIES CUDA_STANDARD 17 CUDA_SEPARABLE_COMPILATION OFF)
  target_compile_options(coredem-bench PRIVATE $<$<COMPILE_LANGUAGE:CUDA>:--expt-relaxed-constexpr>)
  target_link_libraries(coredem-bench PRIVATE CUDA::cudart)
endif()
