# Script mode (cmake -P), run by the ctest "install_consumer" (tests/install.cmake).
# Inputs: NHDYN_SOURCE_DIR, CONSUMER_SOURCE_DIR, WORK_DIR, CXX_COMPILER, GENERATOR.
# Steps, each failing the test with the tool's output:
#   1. configure NHDYN_SOURCE_DIR into WORK_DIR/nhdyn-build (library only)
#   2. cmake --install it --prefix WORK_DIR/prefix
#   3. configure CONSUMER_SOURCE_DIR with CMAKE_PREFIX_PATH = that prefix
#   4. build it
#   5. run it (it checks closed-form results and returns non-zero on a mismatch)
foreach(v NHDYN_SOURCE_DIR CONSUMER_SOURCE_DIR WORK_DIR CXX_COMPILER GENERATOR)
  if(NOT DEFINED ${v} OR "${${v}}" STREQUAL "")
    message(FATAL_ERROR "run_install_test.cmake: ${v} is not set")
  endif()
endforeach()

set(nhdyn_build "${WORK_DIR}/nhdyn-build")
set(prefix "${WORK_DIR}/prefix")
set(build "${WORK_DIR}/consumer-build")
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "${what}:\n${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "install test: ${what} failed (exit ${rc})")
  endif()
endfunction()

step("configure nhdyn (library only)"
  "${CMAKE_COMMAND}" -S "${NHDYN_SOURCE_DIR}" -B "${nhdyn_build}" -G "${GENERATOR}"
  "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" -DCMAKE_BUILD_TYPE=Release
  -DNHDYN_BUILD_TESTS=OFF -DNHDYN_BUILD_EXAMPLES=OFF -DNHDYN_BUILD_BENCH=OFF)
step("install nhdyn into ${prefix}" "${CMAKE_COMMAND}" --install "${nhdyn_build}" --prefix "${prefix}")

# The installed tree must hold the headers and the package files.
file(GLOB_RECURSE config_files "${prefix}/*/nhdynConfig.cmake")
if(NOT EXISTS "${prefix}/include/nhdyn/nhdyn.hpp" OR NOT config_files)
  message(FATAL_ERROR "install test: ${prefix} lacks include/nhdyn/nhdyn.hpp or nhdynConfig.cmake")
endif()

step("configure the consumer"
  "${CMAKE_COMMAND}" -S "${CONSUMER_SOURCE_DIR}" -B "${build}" -G "${GENERATOR}"
  "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" -DCMAKE_BUILD_TYPE=Release
  "-DCMAKE_PREFIX_PATH=${prefix}" "-DEXPECTED_PREFIX=${prefix}"
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
step("build the consumer" "${CMAKE_COMMAND}" --build "${build}")
step("run the consumer" "${build}/nhdyn_consumer")
