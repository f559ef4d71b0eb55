# The shipped machines' generated models.
#
# The build generates them, with their C APIs (<machine>_c.h, <machine>_c.cpp), into its own tree
# (${WEILGEN_GENERATED_DIR}) and compiles those into weilgen; it never writes into the source tree. The committed copies in generated/ are golden
# files: the CTest `generated_files_current` fails when any differs from fresh generation, and
# the target `update_generated` (cmake --build build --target update_generated) rewrites them.
file(GLOB WEILGEN_SHIPPED_MACHINES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/machines/*.yaml)
set(WEILGEN_GENERATED_DIR ${PROJECT_BINARY_DIR}/generated)
set(WEILGEN_SHIPPED_MODELS)
set(outputs)
foreach(machine_file IN LISTS WEILGEN_SHIPPED_MACHINES)
  get_filename_component(machine ${machine_file} NAME_WE)
  list(APPEND WEILGEN_SHIPPED_MODELS ${machine})
  list(APPEND outputs ${WEILGEN_GENERATED_DIR}/${machine}.hpp ${WEILGEN_GENERATED_DIR}/${machine}.md
    ${WEILGEN_GENERATED_DIR}/${machine}_c.h ${WEILGEN_GENERATED_DIR}/${machine}_c.cpp)
endforeach()
add_custom_command(
  OUTPUT ${outputs}
  COMMAND weilgen_generate generate ${WEILGEN_SHIPPED_MACHINES} --out ${WEILGEN_GENERATED_DIR} --c-api
  # generate leaves unchanged files alone; touch them so the outputs are newer than the inputs.
  COMMAND ${CMAKE_COMMAND} -E touch_nocreate ${outputs}
  DEPENDS weilgen_generate ${WEILGEN_SHIPPED_MACHINES}
  COMMENT "Generating the shipped models into ${WEILGEN_GENERATED_DIR}"
  VERBATIM)
add_custom_target(weilgen_generated ALL DEPENDS ${outputs})

# The identified controller parameters of the example (scripts/regenerate_params.sh).
set(WEILGEN_PARAMS_HEADER ${WEILGEN_GENERATED_DIR}/vmc_3axis_params.hpp)

add_custom_target(update_generated
  COMMAND weilgen generate ${WEILGEN_SHIPPED_MACHINES} --out ${PROJECT_SOURCE_DIR}/generated --c-api
  COMMAND weilgen identify vmc_3axis --data ${PROJECT_SOURCE_DIR}/examples/data/vmc_3axis_points.csv
          --emit-params ${PROJECT_SOURCE_DIR}/generated/vmc_3axis_params.hpp --quiet
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
  COMMENT "Rewriting the committed generated/ files"
  VERBATIM)

# The example controller's identified parameters, written into the build tree like the models.
add_custom_command(
  OUTPUT ${WEILGEN_PARAMS_HEADER}
  COMMAND weilgen identify vmc_3axis --data ${PROJECT_SOURCE_DIR}/examples/data/vmc_3axis_points.csv
          --emit-params ${WEILGEN_PARAMS_HEADER} --quiet
  DEPENDS weilgen ${PROJECT_SOURCE_DIR}/examples/data/vmc_3axis_points.csv
          ${PROJECT_SOURCE_DIR}/machines/vmc_3axis.yaml
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
  COMMENT "Identifying the example controller's parameters into ${WEILGEN_PARAMS_HEADER}"
  VERBATIM)
add_custom_target(weilgen_generated_params ALL DEPENDS ${WEILGEN_PARAMS_HEADER})
