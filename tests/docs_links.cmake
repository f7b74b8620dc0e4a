# ctest "docs_links": every relative link in README.md and docs/*.md resolves to a file of the
# repository, and every #anchor to a heading of its page (tests/docs/check_links.py).
find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  add_test(NAME docs_links COMMAND Python3::Interpreter ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_links.py ${PROJECT_SOURCE_DIR})
else()
  message(STATUS "nhdyn: no Python 3 interpreter, the docs_links test is not built")
endif()
# ctest "layers": no header includes one from a layer above its own (tests/docs/check_layers.py
# lists the layers).
if(Python3_Interpreter_FOUND)
  add_test(NAME layers COMMAND Python3::Interpreter ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_layers.py ${PROJECT_SOURCE_DIR})
endif()
