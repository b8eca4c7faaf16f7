# Common compile flags for the project's own C++ (not for OpenFOAM translation units).
add_library(coredem_warnings INTERFACE)
target_compile_options(coredem_warnings INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wno-unused-parameter>)
# GCC notes that passing a 32-byte vector changes the ABI without AVX: kernels::Double4 lives
# only inside the contact module's AVX functions (every call there is inlined), never at an
# interface.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(coredem_warnings INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-Wno-psabi>)
endif()
if(COREDEM_ENABLE_ASSERTS)
  add_compile_definitions(COREDEM_ENABLE_ASSERTS=1)
endif()
