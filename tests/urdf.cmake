# URDF import (io/urdf.hpp) needs nhdyn::urdf (urdfdom, tinyxml2); its test also compares with
# Orocos KDL's tree solver when KDL is present (the KDL tree is built from urdfdom's model in
# the test: Debian's kdl_parser would link all of ROS).
if(TARGET test_urdf)
  if(TARGET nhdyn::urdf)
    target_link_libraries(test_urdf PRIVATE nhdyn::urdf)
    find_package(orocos_kdl QUIET)
    if(orocos_kdl_FOUND)
      target_include_directories(test_urdf SYSTEM PRIVATE ${orocos_kdl_INCLUDE_DIRS})
      target_link_libraries(test_urdf PRIVATE ${orocos_kdl_LIBRARIES})
      target_compile_definitions(test_urdf PRIVATE NHDYN_HAVE_KDL=1)
    endif()
  else()
    message(STATUS "nhdyn tests: urdfdom or tinyxml2 not found: test_urdf is not built")
    set_target_properties(test_urdf PROPERTIES EXCLUDE_FROM_ALL TRUE)
    set_tests_properties(test_urdf PROPERTIES DISABLED TRUE)
  endif()
endif()
# docs/api.md's URDF snippet
if(TARGET test_docs_examples AND TARGET nhdyn::urdf)
  target_link_libraries(test_docs_examples PRIVATE nhdyn::urdf)
  target_compile_definitions(test_docs_examples PRIVATE NHDYN_HAVE_URDF=1)
endif()
