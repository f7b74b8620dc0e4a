# Script mode (cmake -P), run by the ctest "docs_worked_example" (tests/docs_worked_example.cmake).
# Runs PROGRAM (examples/paper5_worked) and fails unless every line it prints that carries
# a number of the example appears verbatim in DOC (docs/theory.md). Lines that print
# rounding-level residuals (|…| norms, qdᵀAᵀλ) are skipped: their last digits depend on
# the compiler and flags, and the page says what they mean, not what they are.
execute_process(COMMAND "${PROGRAM}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} failed (exit ${rc}):\n${out}${err}")
endif()
file(READ "${DOC}" doc)
# Square brackets and semicolons would confuse CMake's list splitting: neutralise them in both.
foreach(text out doc)
  string(REPLACE "[" "<" ${text} "${${text}}")
  string(REPLACE "]" ">" ${text} "${${text}}")
  string(REPLACE ";" "," ${text} "${${text}}")
  string(REPLACE "-0.000000000" " 0.000000000" ${text} "${${text}}")  # the sign of a 1e-17 is noise
endforeach()
string(REPLACE "\n" ";" lines "${out}")
set(missing "")
set(checked 0)
foreach(line IN LISTS lines)
  if(line MATCHES "[0-9]\\.[0-9]" AND NOT line MATCHES "\\|" AND NOT line MATCHES "qd\\^T A\\^T")
    string(FIND "${doc}" "${line}" at)
    math(EXPR checked "${checked} + 1")
    if(at EQUAL -1)
      string(APPEND missing "  ${line}\n")
    endif()
  endif()
endforeach()
if(missing)
  message(FATAL_ERROR "docs/theory.md §8 no longer quotes these lines of paper5_worked's output; "
                      "rerun the program and paste its output into the page:\n${missing}")
endif()
message(STATUS "docs_worked_example: ${checked} lines of paper5_worked's output found in ${DOC}")
