# Runs a study with TOOL in one process and under MPIEXEC with 2 processes, then
# compare_summaries.py: the same runs, bit for bit, and both ranks used.
file(REMOVE_RECURSE ${OUT}/one ${OUT}/many)
execute_process(COMMAND ${TOOL} simulate ${SCENE} --out ${OUT}/one --no-plots --threads 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "one process: exit status ${rc}\n${out}\n${err}")
endif()
execute_process(COMMAND ${MPIEXEC} ${MPIEXEC_NUMPROC_FLAG} 2 --oversubscribe ${TOOL} simulate ${SCENE} --out ${OUT}/many --no-plots
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mpirun -n 2: exit status ${rc}\n${out}\n${err}")
endif()
string(FIND "${out}" "2 MPI processes" at)
if(at EQUAL -1)
  message(FATAL_ERROR "mpirun -n 2: stdout lacks '2 MPI processes':\n${out}\n${err}")
endif()
execute_process(COMMAND ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/compare_summaries.py ${OUT}/one/summary.json ${OUT}/many/summary.json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "summaries differ:\n${out}\n${err}")
endif()
message(STATUS "${out}")
