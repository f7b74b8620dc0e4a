# Fuzzing (issue 6). Two parts:
#  - always: tests/test_fuzz_regression.cpp replays the kept corpus tests/fuzz/corpus/<target>/*
#    through the same entry points as the fuzz targets (tests/fuzz/entry_points.hpp); the tool
#    part is compiled in when the nhdyn tool is (NHDYN_BUILD_EXAMPLES).
#  - with -DNHDYN_FUZZ=ON and clang (scripts/fuzz.sh): libFuzzer targets fuzz_<target> built
#    with -fsanitize=fuzzer,address,undefined.
option(NHDYN_FUZZ "Build the libFuzzer targets (clang only; see scripts/fuzz.sh)" OFF)

set(NHDYN_FUZZ_DIR ${CMAKE_CURRENT_SOURCE_DIR}/fuzz)
# The tool's sources without main.cpp (the fuzz targets compile them with their own flags).
set(NHDYN_TOOL_LIB_SOURCES "")
if(TARGET nhdyn_tool_objects)
  get_target_property(NHDYN_TOOL_LIB_SOURCES nhdyn_tool_objects SOURCES)
endif()

nhdyn_test_target(test_fuzz_regression _target)
if(TARGET ${_target})
  find_package(nlohmann_json 3 REQUIRED)
  target_link_libraries(${_target} PRIVATE nlohmann_json::nlohmann_json)
  target_include_directories(${_target} PRIVATE ${NHDYN_FUZZ_DIR})
  if(TARGET nhdyn_tool_objects)
    target_link_libraries(${_target} PRIVATE nhdyn_tool_objects)
    target_compile_definitions(${_target} PRIVATE NHDYN_FUZZ_TOOL=1)
  endif()
endif()

if(NHDYN_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "NHDYN_FUZZ needs clang (libFuzzer), e.g. -DCMAKE_CXX_COMPILER=clang++-14")
  endif()
  find_package(nlohmann_json 3 REQUIRED)
  set(_fuzz_flags -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer -g)
  function(nhdyn_fuzz_target name)
    add_executable(fuzz_${name} ${NHDYN_FUZZ_DIR}/fuzz_${name}.cpp ${ARGN})
    target_link_libraries(fuzz_${name} PRIVATE nhdyn::nhdyn nlohmann_json::nlohmann_json)
    target_compile_options(fuzz_${name} PRIVATE ${_fuzz_flags})
    target_link_options(fuzz_${name} PRIVATE ${_fuzz_flags})
    target_include_directories(fuzz_${name} PRIVATE ${NHDYN_FUZZ_DIR} ${PROJECT_SOURCE_DIR}/examples/nhdyn_tool)
    set_target_properties(fuzz_${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR})
  endfunction()
  nhdyn_fuzz_target(model_json)
  if(NHDYN_TOOL_LIB_SOURCES)
    nhdyn_fuzz_target(tool_lines ${NHDYN_TOOL_LIB_SOURCES})
  endif()
  if(EXISTS ${NHDYN_FUZZ_DIR}/fuzz_scene.cpp)
    nhdyn_fuzz_target(scene ${NHDYN_FUZZ_SCENE_SOURCES})
  endif()
endif()
