# coredem-bench dem: the DEM core on the packed / agitated decks (bench/decks.md); the hopper
# deck's settling and deck files in hopper/ (not a command of its own).
target_sources(coredem-bench PRIVATE ${CMAKE_CURRENT_LIST_DIR}/hopper/deck.cpp)
target_link_libraries(coredem-bench PRIVATE coredem::dem)
