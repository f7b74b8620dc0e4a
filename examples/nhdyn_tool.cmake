# The `nhdyn` command-line tool (target nhdyn_tool, executable `nhdyn`, since the library
# target is already called nhdyn): examples/nhdyn_tool/*.cpp — main.cpp's registry,
# tool.cpp's shared line loop, one file per subcommand. Needs nlohmann_json (Debian
# nlohmann-json3-dev) and CLI11 (libcli11-dev). Everything but main.cpp is compiled once, into
# the object library nhdyn_tool_objects, which the fuzz regression test links too
# (tests/fuzz.cmake). The executable goes to <build>/bin, beside <build>/share/nhdyn (the
# shipped data), as in an installed tree: it finds its data from its own location.
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 2 REQUIRED)
file(GLOB NHDYN_TOOL_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/nhdyn_tool/*.cpp)
list(FILTER NHDYN_TOOL_SOURCES EXCLUDE REGEX "/main\\.cpp$")
add_library(nhdyn_tool_objects OBJECT ${NHDYN_TOOL_SOURCES})
target_link_libraries(nhdyn_tool_objects PUBLIC nhdyn::json nhdyn::boost CLI11::CLI11
                                         PRIVATE nhdyn_project_options nhdyn_program_options)
target_include_directories(nhdyn_tool_objects PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/nhdyn_tool)
if(TARGET nhdyn::urdf)  # --model x.urdf
  nhdyn_link_loaders(nhdyn_tool_objects PUBLIC)  # nhdyn::compiled where it is built
  target_compile_definitions(nhdyn_tool_objects PRIVATE NHDYN_TOOL_URDF=1)
endif()
# `mpirun -n N nhdyn simulate …` (Debian's libopenmpi-dev, openmpi-bin): runs spread over
# processes and machines. Without MPI the tool runs on threads only.
set(MPI_CXX_SKIP_MPICXX ON)  # the C API from C++; not the deprecated C++ bindings
find_package(MPI COMPONENTS CXX QUIET)
if(MPI_CXX_FOUND)
  target_link_libraries(nhdyn_tool_objects PUBLIC MPI::MPI_CXX)
  target_compile_definitions(nhdyn_tool_objects PRIVATE NHDYN_TOOL_MPI=1)
  message(STATUS "nhdyn: MPI found (${MPI_CXX_LIB_NAMES}): nhdyn simulate runs under mpirun")
else()
  message(STATUS "nhdyn: MPI not found (libopenmpi-dev): nhdyn simulate uses threads only")
endif()
add_executable(nhdyn_tool ${CMAKE_CURRENT_SOURCE_DIR}/nhdyn_tool/main.cpp)
set_target_properties(nhdyn_tool PROPERTIES OUTPUT_NAME nhdyn RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/${CMAKE_INSTALL_BINDIR})
target_link_libraries(nhdyn_tool PRIVATE nhdyn_tool_objects nhdyn_project_options nhdyn_program_options)
add_dependencies(nhdyn_tool nhdyn_data)
if(TARGET nhdyn_viewer)  # nhdyn view's page template
  add_dependencies(nhdyn_tool nhdyn_viewer)
endif()
install(TARGETS nhdyn_tool RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
