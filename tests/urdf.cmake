# URDF import (io/urdf.hpp) and robot files need nhdyn::urdf (urdfdom, tinyxml2); test_urdf also compares with
# Orocos KDL's tree solver when KDL is present (the KDL tree is built from urdfdom's model in
# the test: Debian's kdl_parser would link all of ROS).
# test_urdf (and test_lock, below) use the loaders header-only; the others link nhdyn::compiled
# where it is built (nhdyn_link_loaders), so both ways are compiled and tested.
# A test's program is its group's (tests/CMakeLists.txt, nhdyn_test_target): test_urdf's group
# links nhdyn::urdf header-only, the others' groups nhdyn::compiled.
foreach(t test_urdf test_wheeled_base test_wheel_kinds test_robot_simulation test_derivatives test_scene_terms
        test_robot_dynamics)
  nhdyn_test_target(${t} _target)
  if(TARGET ${_target})
    if(TARGET nhdyn::urdf AND t STREQUAL "test_urdf")
      target_link_libraries(${_target} PRIVATE nhdyn::urdf)
    elseif(TARGET nhdyn::urdf)
      nhdyn_link_loaders(${_target})
    else()
      nhdyn_skip_test_target(${_target} "urdfdom or tinyxml2 not found")
    endif()
  endif()
endforeach()
nhdyn_test_target(test_urdf _target)
if(TARGET ${_target} AND TARGET nhdyn::urdf)
  find_package(orocos_kdl QUIET)
  if(orocos_kdl_FOUND)
    target_include_directories(${_target} SYSTEM PRIVATE ${orocos_kdl_INCLUDE_DIRS})
    target_link_libraries(${_target} PRIVATE ${orocos_kdl_LIBRARIES})
    target_compile_definitions(${_target} PRIVATE NHDYN_HAVE_KDL=1)
  endif()
endif()
# docs/api.md's URDF snippet
nhdyn_test_target(test_docs_examples _target)
if(TARGET ${_target} AND TARGET nhdyn::urdf)
  nhdyn_link_loaders(${_target})
  target_compile_definitions(${_target} PRIVATE NHDYN_HAVE_URDF=1)
endif()
# tests/test_lock.cpp compares lock() with the URDF loader's merge of fixed joints when it can
nhdyn_test_target(test_lock _target)
if(TARGET ${_target} AND TARGET nhdyn::urdf)
  target_link_libraries(${_target} PRIVATE nhdyn::urdf)
  target_compile_definitions(${_target} PRIVATE NHDYN_HAVE_URDF=1)
endif()
