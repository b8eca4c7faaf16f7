# coredem_common: error-checking macros and named loggers shared by every component.
add_library(coredem_common STATIC ${CMAKE_CURRENT_LIST_DIR}/src/common/log.cpp)
add_library(coredem::common ALIAS coredem_common)
target_include_directories(coredem_common PUBLIC ${CMAKE_CURRENT_LIST_DIR}/include)
target_link_libraries(coredem_common PUBLIC spdlog::spdlog PRIVATE coredem_warnings)
