# nhdyn::compiled (include/nhdyn/config.hpp, issue 33 item 4): the same program built linking
# the compiled loaders and header-only gives the same numbers bit for bit. Both programs are
# built with the library's flags (the build type's and NHDYN_PROGRAM_OPT, not NHDYN_TEST_OPT):
# what is compared is where the functions are compiled, not how.
if(TARGET nhdyn_compiled)
  add_executable(compiled_same_numbers compiled/same_numbers.cpp)
  target_link_libraries(compiled_same_numbers PRIVATE nhdyn::nhdyn nhdyn::compiled nhdyn_project_options nhdyn_program_options)
  add_executable(compiled_same_numbers_header_only compiled/same_numbers.cpp)
  target_link_libraries(compiled_same_numbers_header_only PRIVATE nhdyn::nhdyn nhdyn::urdf nhdyn::json nhdyn::boost nhdyn_project_options nhdyn_program_options)
  add_test(NAME compiled_same_numbers
    COMMAND ${CMAKE_COMMAND} -DCOMPILED=$<TARGET_FILE:compiled_same_numbers>
            -DHEADER_ONLY=$<TARGET_FILE:compiled_same_numbers_header_only>
            -DROBOTS=${PROJECT_SOURCE_DIR}/examples/robots -DSCENES=${PROJECT_SOURCE_DIR}/examples/scenes
            -DWORK=${CMAKE_CURRENT_BINARY_DIR}
            -P ${CMAKE_CURRENT_SOURCE_DIR}/compiled/compare.cmake)
endif()
