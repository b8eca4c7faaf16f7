# coredem-bench protocol: round-trip throughput of the ZeroMQ transport vs memcpy. ZeroMQ is
# linked only for the opt-in "tcp-raw" baseline (bare cppzmq, bypassing coredem::protocol).
target_link_libraries(coredem-bench PRIVATE coredem::protocol coredem::zmq Threads::Threads)
