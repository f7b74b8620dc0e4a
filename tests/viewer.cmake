# `nhdyn view` in a real browser (tests/viewer/test_view.cpp): needs the page template (the
# build makes it with node: NHDYN_HAVE_VIEWER, top-level CMakeLists.txt), puppeteer-core from
# viewer/node_modules (scripts/install-deps.sh) and Debian's chromium.
find_program(NHDYN_CHROMIUM NAMES chromium chromium-browser)
if(TARGET nhdyn_tool AND TARGET nhdyn::urdf AND NHDYN_HAVE_VIEWER AND NHDYN_CHROMIUM
   AND EXISTS ${PROJECT_SOURCE_DIR}/viewer/node_modules/puppeteer-core/package.json)
  nhdyn_add_test(tool_test_view ${CMAKE_CURRENT_SOURCE_DIR}/viewer/test_view.cpp)
  target_link_libraries(tool_test_view PRIVATE nlohmann_json::nlohmann_json)
  nhdyn_link_loaders(tool_test_view)
  target_compile_definitions(tool_test_view PRIVATE NHDYN_TOOL_PATH="$<TARGET_FILE:nhdyn_tool>"
                                                    NHDYN_NODE="${NHDYN_NODE}" NHDYN_CHROMIUM="${NHDYN_CHROMIUM}")
  add_dependencies(tool_test_view nhdyn_tool)
else()
  message(STATUS "nhdyn tests: no browser test of nhdyn view (needs node, viewer/node_modules, chromium, urdfdom)")
endif()
