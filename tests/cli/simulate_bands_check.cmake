# Runs a study of more than 20 runs with figures, then check_bands.py: the percentile bands
# equal NumPy's percentiles of the runs' CSVs, and the band figures exist (when gnuplot is
# installed).
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${TOOL} simulate ${SCENE} --out ${OUT} --threads 2
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "exit status ${rc}\n${out}\n${err}")
endif()
find_program(GNUPLOT gnuplot)
set(figures "")
if(GNUPLOT)
  set(figures --figures)
endif()
execute_process(COMMAND ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/check_bands.py ${OUT} ${GROUP} ${RUNS} ${figures}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "bands:\n${out}\n${err}")
endif()
message(STATUS "${out}")
