# coredem-bench dem: the DEM core on the packed / agitated decks (bench/decks.md).
target_link_libraries(coredem-bench PRIVATE coredem::dem)
