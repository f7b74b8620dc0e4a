# Runs TOOL simulate SCENE --out OUT --no-plots; checks the exit status (EXPECT_RC), that
# stdout contains EXPECT_TEXT, that OUT/RUN.csv starts with the documented header and that
# OUT/summary.json names the run.
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${TOOL} simulate ${SCENE} --out ${OUT} --no-plots
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL EXPECT_RC)
  message(FATAL_ERROR "exit status ${rc}, expected ${EXPECT_RC}\n${out}\n${err}")
endif()
string(FIND "${out}" "${EXPECT_TEXT}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "stdout lacks '${EXPECT_TEXT}':\n${out}\n${err}")
endif()
file(STRINGS ${OUT}/${RUN}.csv header LIMIT_COUNT 1)
if(NOT header STREQUAL "t,q1,q2,q3,q4,q5,eta1,eta2,eta3,eta4,tau1,tau2,tau3,tau4,r_x,r_y,r_z,rd_x,rd_y,rd_z,err")
  message(FATAL_ERROR "CSV header is '${header}'")
endif()
file(READ ${OUT}/summary.json summary)
string(FIND "${summary}" "\"name\": \"${RUN}\"" at)
if(at EQUAL -1)
  message(FATAL_ERROR "summary.json lacks run ${RUN}:\n${summary}")
endif()
