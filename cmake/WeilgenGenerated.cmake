# Regenerates the committed models in generated/ when a machine file or the generator changes.
file(GLOB WEILGEN_SHIPPED_MACHINES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/machines/*.yaml)
set(WEILGEN_GENERATED_OUTPUTS)
foreach(machine_file IN LISTS WEILGEN_SHIPPED_MACHINES)
  get_filename_component(machine ${machine_file} NAME_WE)
  list(APPEND WEILGEN_GENERATED_OUTPUTS
    ${CMAKE_CURRENT_SOURCE_DIR}/generated/${machine}.hpp
    ${CMAKE_CURRENT_SOURCE_DIR}/generated/${machine}.md)
endforeach()
if(WEILGEN_REGENERATE)
  add_custom_command(
    OUTPUT ${CMAKE_CURRENT_BINARY_DIR}/generated.stamp
    COMMAND weilgen generate ${WEILGEN_SHIPPED_MACHINES} --out ${CMAKE_CURRENT_SOURCE_DIR}/generated
    COMMAND ${CMAKE_COMMAND} -E touch ${CMAKE_CURRENT_BINARY_DIR}/generated.stamp
    DEPENDS weilgen ${WEILGEN_SHIPPED_MACHINES}
    COMMENT "Regenerating generated/ from machines/*.yaml"
    VERBATIM)
  add_custom_target(weilgen_generated ALL DEPENDS ${CMAKE_CURRENT_BINARY_DIR}/generated.stamp)
endif()
