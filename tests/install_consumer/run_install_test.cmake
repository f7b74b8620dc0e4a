# Script mode (cmake -P), run by the ctest "install_consumer" (tests/install.cmake).
# Inputs: BUILD_DIR, VERSION, CONSUMER_SOURCE_DIR, WORK_DIR, CXX_COMPILER, GENERATOR, WITH_TOOL.
# Each step fails the test with its output.
foreach(v BUILD_DIR VERSION CONSUMER_SOURCE_DIR WORK_DIR CXX_COMPILER GENERATOR)
  if(NOT DEFINED ${v} OR "${${v}}" STREQUAL "")
    message(FATAL_ERROR "run_install_test.cmake: ${v} is not set")
  endif()
endforeach()

set(prefix "${WORK_DIR}/prefix")
set(build "${WORK_DIR}/consumer-build")
set(elsewhere "${WORK_DIR}/elsewhere")  # a current folder outside the source, build and install trees
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${elsewhere}")

function(step what)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY "${elsewhere}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "${what}:\n${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "install test: ${what} failed (exit ${rc})")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

step("install the build tree into ${prefix}" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}")

# The installed tree holds the headers, the package files and the shipped data.
file(GLOB_RECURSE config_files "${prefix}/*/nhdynConfig.cmake")
foreach(f include/nhdyn/nhdyn.hpp include/nhdyn/version.hpp share/nhdyn/scenes/paper.json
          share/nhdyn/models/paper5.json share/nhdyn/models/puma560.json)
  if(NOT EXISTS "${prefix}/${f}")
    message(FATAL_ERROR "install test: ${prefix} lacks ${f}")
  endif()
endforeach()
if(NOT config_files)
  message(FATAL_ERROR "install test: ${prefix} lacks nhdynConfig.cmake")
endif()

if(WITH_TOOL)
  set(tool "${prefix}/bin/nhdyn")
  if(NOT EXISTS "${tool}")
    message(FATAL_ERROR "install test: ${prefix}/bin/nhdyn was not installed")
  endif()
  step("nhdyn --version" "${tool}" --version)
  if(NOT step_output STREQUAL "nhdyn ${VERSION}\n")
    message(FATAL_ERROR "install test: nhdyn --version printed '${step_output}', expected 'nhdyn ${VERSION}'")
  endif()
  step("installed nhdyn simulate paper, run from ${elsewhere}"
       "${CMAKE_COMMAND}" -E env --unset=NHDYN_SCENES_DIR "${tool}" simulate paper --out out --no-plots)
  foreach(text "paper-circle: 1/1 succeeded" "paper-factorial: 16/16 succeeded" "paper-noise: 16/16 succeeded")
    string(FIND "${step_output}" "${text}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "install test: nhdyn simulate paper did not print '${text}'")
    endif()
  endforeach()
endif()

# A separate project that uses the installed package: every header on its own, and a program.
file(GLOB_RECURSE headers RELATIVE "${prefix}/include" "${prefix}/include/nhdyn/*.hpp")
list(LENGTH headers n_headers)
if(n_headers LESS 30)
  message(FATAL_ERROR "install test: only ${n_headers} headers installed")
endif()
string(REPLACE ";" "\\;" headers_arg "${headers}")
step("configure the consumer"
  "${CMAKE_COMMAND}" -S "${CONSUMER_SOURCE_DIR}" -B "${build}" -G "${GENERATOR}"
  "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" -DCMAKE_BUILD_TYPE=Release
  "-DCMAKE_PREFIX_PATH=${prefix}" "-DEXPECTED_PREFIX=${prefix}" "-DEXPECTED_VERSION=${VERSION}"
  "-DNHDYN_HEADERS=${headers_arg}"
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
step("build the consumer (one translation unit per installed header, and the program)"
     "${CMAKE_COMMAND}" --build "${build}" -j 2)
step("run the consumer" "${build}/nhdyn_consumer")
if(EXISTS "${build}/nhdyn_consumer_compiled")
  step("run the consumer of nhdyn::compiled"
       "${build}/nhdyn_consumer_compiled" "${prefix}/share/nhdyn/robots/mobile_manipulator_wheels.json")
elseif(EXISTS "${prefix}/lib/libnhdyn_compiled.a" OR EXISTS "${prefix}/lib64/libnhdyn_compiled.a")
  message(FATAL_ERROR "install test: libnhdyn_compiled.a is installed but the consumer found no nhdyn::compiled")
endif()
