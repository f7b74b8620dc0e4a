# The short examples run as tests: each checks its own result and exits non-zero when it is
# wrong (the LQR must stabilise the motion, the bounds must enclose the sampled corners, the
# wheel-speed stage must agree with the plain pipeline, …). readme_example and paper5_worked
# have their own checks (readme.cmake, docs_worked_example.cmake); long_horizon and
# work_precision are studies of minutes, run by hand (docs/accuracy.md).
foreach(example bound_paper5 lqr_paper5 paper5_id wheel_speed_stage wheeled_robot mecanum_base)
  if(TARGET ${example})
    add_test(NAME example_${example} COMMAND ${example})
  endif()
endforeach()
