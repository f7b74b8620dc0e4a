# ctest "docs_worked_example": docs/theory.md §8 quotes the output of
# examples/paper5_worked; this keeps the quote in step with the program. It is a
# documentation check, not a correctness test (the numbers themselves are checked against
# independent relations in tests/test_docs_examples.cpp and the other test files).
if(TARGET paper5_worked)
  add_test(NAME docs_worked_example
    COMMAND ${CMAKE_COMMAND}
      "-DPROGRAM=$<TARGET_FILE:paper5_worked>"
      "-DDOC=${PROJECT_SOURCE_DIR}/docs/theory.md"
      -P "${CMAKE_CURRENT_SOURCE_DIR}/docs/check_worked_example.cmake")
endif()
