# Fails unless README.md's C++ example is exactly examples/readme_example.cpp (which is built
# and run as a test), so the front door's example always compiles and runs.
file(READ ${README} readme)
file(READ ${EXAMPLE} example)
string(FIND "${readme}" "```cpp\n${example}```" at)
if(at EQUAL -1)
  message(FATAL_ERROR "README.md's ```cpp block differs from examples/readme_example.cpp: keep them identical")
endif()
