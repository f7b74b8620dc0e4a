# ctest "install_consumer" (issue 2, item 1): configure this source tree afresh (library
# only: tests, examples and benchmarks off), `cmake --install` it into a temporary prefix,
# then configure, build and run a separate tiny project (tests/install_consumer/) that does
# find_package(nhdyn) and links nhdyn::nhdyn. A fresh configure keeps the test independent
# of which targets of this build tree happen to be built. Everything happens under this
# build folder; nothing is downloaded.
add_test(NAME install_consumer
  COMMAND ${CMAKE_COMMAND}
    "-DNHDYN_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
    "-DCONSUMER_SOURCE_DIR=${CMAKE_CURRENT_SOURCE_DIR}/install_consumer"
    "-DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/install_consumer_work"
    "-DCXX_COMPILER=${CMAKE_CXX_COMPILER}"
    "-DGENERATOR=${CMAKE_GENERATOR}"
    -P "${CMAKE_CURRENT_SOURCE_DIR}/install_consumer/run_install_test.cmake")
set_tests_properties(install_consumer PROPERTIES TIMEOUT 900)
