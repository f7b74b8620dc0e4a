# Model-file tests need nlohmann_json; the tool's tests drive the built `nhdyn` binary
# (target nhdyn_tool, from examples/nhdyn_tool.cmake), whose path they get as
# NHDYN_TOOL_PATH. tests/tool/test_*.cpp each become one executable and ctest entry.
find_package(nlohmann_json 3 REQUIRED)
nhdyn_test_target(test_model_io _target)
if(TARGET ${_target})
  target_link_libraries(${_target} PRIVATE nlohmann_json::nlohmann_json)
endif()
if(TARGET nhdyn_tool)
  file(GLOB NHDYN_TOOL_TEST_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/tool/test_*.cpp)
  if(NOT TARGET nhdyn::urdf)  # tool/test_tool_model.cpp drives URDF models
    list(FILTER NHDYN_TOOL_TEST_SOURCES EXCLUDE REGEX "/test_tool_model\\.cpp$")
  endif()
  foreach(src ${NHDYN_TOOL_TEST_SOURCES})
    get_filename_component(name ${src} NAME_WE)
    set(name tool_${name})
    add_executable(${name} ${src})
    target_link_libraries(${name} PRIVATE nhdyn::nhdyn nhdyn_catch_main nhdyn_project_options nlohmann_json::nlohmann_json)
    target_include_directories(${name} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
    target_compile_definitions(${name} PRIVATE NHDYN_TOOL_PATH="$<TARGET_FILE:nhdyn_tool>"
                                                "NHDYN_SOURCE_DIR=\"${PROJECT_SOURCE_DIR}\"")
    if(TARGET nhdyn::urdf)
      nhdyn_link_loaders(${name})
    endif()
    add_dependencies(${name} nhdyn_tool)
    add_test(NAME ${name} COMMAND ${name} --use-colour no)
  endforeach()
endif()
