# Orocos KDL as an independent reference for the tests (issue 2, item 7 iii): Debian's
# liborocos-kdl-dev. tests/test_kdl_reference.cpp is built either way; without KDL it only
# reports that the comparison was skipped.
find_package(orocos_kdl QUIET)
nhdyn_test_target(test_kdl_reference _target)
if(TARGET ${_target})
  if(orocos_kdl_FOUND)
    target_include_directories(${_target} SYSTEM PRIVATE ${orocos_kdl_INCLUDE_DIRS})
    target_link_libraries(${_target} PRIVATE ${orocos_kdl_LIBRARIES})
    target_compile_definitions(${_target} PRIVATE NHDYN_HAVE_KDL=1)
  else()
    message(STATUS "nhdyn tests: Orocos KDL (liborocos-kdl-dev) not found: test_kdl_reference is skipped")
  endif()
endif()
