# The README's example: identical to examples/readme_example.cpp, which must build and run.
add_test(NAME readme_example_matches_file
  COMMAND ${CMAKE_COMMAND} -DREADME=${PROJECT_SOURCE_DIR}/README.md
          -DEXAMPLE=${PROJECT_SOURCE_DIR}/examples/readme_example.cpp
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/readme_example_check.cmake)
if(TARGET readme_example)
  add_test(NAME readme_example_runs COMMAND readme_example)
endif()
