# `nhdyn simulate` end to end: exit status, reason on stdout, CSV header, summary.json.
if(TARGET nhdyn_tool)
  set(_sim_check ${CMAKE_CURRENT_SOURCE_DIR}/cli/simulate_check.cmake)
  add_test(NAME simulate_cli_paper_circle_succeeds
    COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:nhdyn_tool> -DSCENE=paper-circle -DRUN=paper-circle
            -DOUT=${CMAKE_CURRENT_BINARY_DIR}/simulate_cli_ok -DEXPECT_RC=0 "-DEXPECT_TEXT=paper-circle: 1/1 succeeded"
            -P ${_sim_check})
  add_test(NAME simulate_cli_failing_run_exits_1_with_reason
    COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:nhdyn_tool> -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/scenes/failing-gains.json
            -DRUN=failing-gains -DOUT=${CMAKE_CURRENT_BINARY_DIR}/simulate_cli_fail -DEXPECT_RC=1
            "-DEXPECT_TEXT=too many steps" -P ${_sim_check})
  # The paper's whole experiment (circle + both 16-run studies, run in parallel): 33/33.
  add_test(NAME simulate_cli_paper_33_of_33
    COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:nhdyn_tool> -DSCENE=paper -DRUN=paper-noise-seed_16
            -DOUT=${CMAKE_CURRENT_BINARY_DIR}/simulate_cli_paper -DEXPECT_RC=0
            "-DEXPECT_TEXT=paper-factorial: 16/16 succeeded" "-DEXPECT_TEXT2=paper-noise: 16/16 succeeded"
            -DEXPECT_SUCCESSES=33 -P ${_sim_check})
  # Any robot: the shipped mobile manipulator's robot file, columns named from its URDF.
  if(TARGET nhdyn::urdf)
    add_test(NAME simulate_cli_mobile_manipulator
      COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:nhdyn_tool> -DSCENE=mobile-manipulator-circle
              -DRUN=mobile-manipulator-circle -DOUT=${CMAKE_CURRENT_BINARY_DIR}/simulate_cli_mm -DEXPECT_RC=0
              "-DEXPECT_TEXT=mobile-manipulator-circle: 1/1 succeeded"
              "-DEXPECT_HEADER_START=t,q_base_x,q_base_y,q_base_yaw,q_wheel_left_joint," -P ${_sim_check})
    # Any model: a URDF arm (holonomic) on a line; a preset under computed torque, with mismatch
    add_test(NAME simulate_cli_urdf_arm_line
      COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:nhdyn_tool> -DSCENE=puma560-line -DRUN=puma560-line
              -DOUT=${CMAKE_CURRENT_BINARY_DIR}/simulate_cli_puma_line -DEXPECT_RC=0 "-DEXPECT_TEXT=puma560-line: 1/1 succeeded"
              "-DEXPECT_HEADER_START=t,q_joint1,q_joint2,q_joint3,q_joint4,q_joint5,q_joint6,eta_joint1," -P ${_sim_check})
    add_test(NAME simulate_cli_computed_torque
      COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:nhdyn_tool> -DSCENE=puma560-computed-torque -DRUN=puma560-computed-torque
              -DOUT=${CMAKE_CURRENT_BINARY_DIR}/simulate_cli_puma_ct -DEXPECT_RC=0
              "-DEXPECT_TEXT=puma560-computed-torque: 1/1 succeeded" "-DEXPECT_HEADER_START=t,q_joint1," -P ${_sim_check})
  endif()
  # Percentile-band figures for many runs: bands = NumPy's percentiles of the runs' CSVs.
  find_package(Python3 COMPONENTS Interpreter QUIET)
  if(Python3_Interpreter_FOUND)
    execute_process(COMMAND ${Python3_EXECUTABLE} -c "import numpy" RESULT_VARIABLE _no_numpy OUTPUT_QUIET ERROR_QUIET)
    if(_no_numpy EQUAL 0)
      add_test(NAME simulate_cli_percentile_bands
        COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:nhdyn_tool> -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/scenes/bands-monte-carlo.json
                -DOUT=${CMAKE_CURRENT_BINARY_DIR}/simulate_cli_bands -DGROUP=bands-mc -DRUNS=24 -DPYTHON=${Python3_EXECUTABLE}
                -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/simulate_bands_check.cmake)
    endif()
  endif()
  # MPI: a Monte Carlo study on 1 process and under mpirun -n 2, the same runs bit for bit
  # (not under sanitizers: Open MPI's start-up is not leak-clean).
  set(MPI_CXX_SKIP_MPICXX ON)
  find_package(MPI COMPONENTS CXX QUIET)
  find_package(Python3 COMPONENTS Interpreter QUIET)
  if(MPI_CXX_FOUND AND MPIEXEC_EXECUTABLE AND Python3_Interpreter_FOUND AND NOT NHDYN_SANITIZE)
    add_test(NAME simulate_cli_mpi_same_results
      COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:nhdyn_tool> -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/scenes/mpi-monte-carlo.json
              -DOUT=${CMAKE_CURRENT_BINARY_DIR}/simulate_cli_mpi -DMPIEXEC=${MPIEXEC_EXECUTABLE}
              -DMPIEXEC_NUMPROC_FLAG=${MPIEXEC_NUMPROC_FLAG} -DPYTHON=${Python3_EXECUTABLE}
              -P ${CMAKE_CURRENT_SOURCE_DIR}/cli/simulate_mpi_check.cmake)
    # Open MPI refuses root unless told (CI and the quick start run as root)
    set_tests_properties(simulate_cli_mpi_same_results PROPERTIES
      ENVIRONMENT "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1")
  endif()
  # No NHDYN_SCENES_DIR: the tool finds its shipped scenes from its own location
  # (<build>/bin/nhdyn, <build>/share/nhdyn/scenes), from the test's folder (the build folder).
endif()
