# The `nhdyn` command-line tool (target nhdyn_tool, executable `nhdyn`, since the library
# target is already called nhdyn): examples/nhdyn_tool/*.cpp — main.cpp's registry,
# tool.cpp's shared line loop, one file per subcommand. Needs nlohmann_json (Debian
# nlohmann-json3-dev).
find_package(nlohmann_json 3 REQUIRED)
include(GNUInstallDirs)
file(GLOB NHDYN_TOOL_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/nhdyn_tool/*.cpp)
add_executable(nhdyn_tool ${NHDYN_TOOL_SOURCES})
set_target_properties(nhdyn_tool PROPERTIES OUTPUT_NAME nhdyn)
target_link_libraries(nhdyn_tool PRIVATE nhdyn::nhdyn nlohmann_json::nlohmann_json nhdyn_project_options)
target_include_directories(nhdyn_tool PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/nhdyn_tool)
install(TARGETS nhdyn_tool RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
