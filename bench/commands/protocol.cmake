# coredem-bench protocol: round-trip throughput of the ZeroMQ transport vs memcpy.
target_link_libraries(coredem-bench PRIVATE coredem::protocol Threads::Threads)
