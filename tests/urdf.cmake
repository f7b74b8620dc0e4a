# URDF import (io/urdf.hpp) and robot files need nhdyn::urdf (urdfdom, tinyxml2); test_urdf also compares with
# Orocos KDL's tree solver when KDL is present (the KDL tree is built from urdfdom's model in
# the test: Debian's kdl_parser would link all of ROS).
# test_urdf (and test_lock, below) use the loaders header-only; the others link nhdyn::compiled
# where it is built (nhdyn_link_loaders), so both ways are compiled and tested.
foreach(t test_urdf test_wheeled_base test_wheel_kinds test_robot_simulation test_derivatives test_scene_terms)
  if(TARGET ${t})
    if(TARGET nhdyn::urdf AND t STREQUAL "test_urdf")
      target_link_libraries(${t} PRIVATE nhdyn::urdf)
    elseif(TARGET nhdyn::urdf)
      nhdyn_link_loaders(${t})
    else()
      message(STATUS "nhdyn tests: urdfdom or tinyxml2 not found: ${t} is not built")
      set_target_properties(${t} PROPERTIES EXCLUDE_FROM_ALL TRUE)
      set_tests_properties(${t} PROPERTIES DISABLED TRUE)
    endif()
  endif()
endforeach()
if(TARGET test_urdf AND TARGET nhdyn::urdf)
  find_package(orocos_kdl QUIET)
  if(orocos_kdl_FOUND)
    target_include_directories(test_urdf SYSTEM PRIVATE ${orocos_kdl_INCLUDE_DIRS})
    target_link_libraries(test_urdf PRIVATE ${orocos_kdl_LIBRARIES})
    target_compile_definitions(test_urdf PRIVATE NHDYN_HAVE_KDL=1)
  endif()
endif()
# docs/api.md's URDF snippet
if(TARGET test_docs_examples AND TARGET nhdyn::urdf)
  nhdyn_link_loaders(test_docs_examples)
  target_compile_definitions(test_docs_examples PRIVATE NHDYN_HAVE_URDF=1)
endif()
# tests/test_lock.cpp compares lock() with the URDF loader's merge of fixed joints when it can
if(TARGET test_lock AND TARGET nhdyn::urdf)
  target_link_libraries(test_lock PRIVATE nhdyn::urdf)
  target_compile_definitions(test_lock PRIVATE NHDYN_HAVE_URDF=1)
endif()
