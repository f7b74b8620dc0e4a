# ctest "install_consumer": `cmake --install` this build tree into a temporary prefix, then use
# it as a user would, from a folder outside both trees:
#   - the installed tool: `nhdyn --version` prints the project's version, `nhdyn simulate
#     paper` finds its shipped scenes (share/nhdyn/scenes) and succeeds 33/33;
#   - a separate project (tests/install_consumer/) does find_package(nhdyn COMPONENTS json boost),
#     compiles one translation unit per installed header (each must stand on its own) and
#     builds and runs a program that checks closed-form results.
# Nothing is downloaded; everything happens under this build folder.
add_test(NAME install_consumer
  COMMAND ${CMAKE_COMMAND}
    "-DBUILD_DIR=${PROJECT_BINARY_DIR}"
    "-DVERSION=${PROJECT_VERSION}"
    "-DCONSUMER_SOURCE_DIR=${CMAKE_CURRENT_SOURCE_DIR}/install_consumer"
    "-DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/install_consumer_work"
    "-DCXX_COMPILER=${CMAKE_CXX_COMPILER}"
    "-DGENERATOR=${CMAKE_GENERATOR}"
    "-DWITH_TOOL=$<TARGET_EXISTS:nhdyn_tool>"
    -P "${CMAKE_CURRENT_SOURCE_DIR}/install_consumer/run_install_test.cmake")
# COST: the longest test (it builds a project): ctest -j starts it first, the rest beside it.
set_tests_properties(install_consumer PROPERTIES TIMEOUT 1800 COST 1000)
