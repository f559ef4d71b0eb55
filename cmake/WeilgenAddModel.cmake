# weilgen_add_model(<target> <machine> [ORDER r] [NAME model] [OUTPUT_DIR dir] [C_API])
#
# Regenerates a machine's error-model header at build time and exposes it as the INTERFACE
# library <target>: link it and `#include "<model>.hpp"` (namespace weilgen_models::<model>).
#
#   <machine>   path to a machine file (relative paths are relative to the current source dir),
#               or the name of a shipped machine (looked up in WEILGEN_MACHINES_DIR).
#   ORDER r     passes --order r; when r differs from the file's algebra.order the model is
#               named <name>_o<r> (as `weilgen generate` names it).
#   NAME model  the generated model's name (header stem and namespace, including any _o<r>).
#               Without it the name is read from the machine file at configure time by a line
#               match, which only understands a top-level `name: <identifier>` line and, with
#               ORDER, `algebra: {order: N}` or an `algebra:` block with an indented `order: N`
#               line (anchors, multi-line flow maps, blank lines inside the block are not
#               understood). Pass NAME when the file is written differently; the build checks
#               that the header it expects was written.
#   C_API       also generates the C API (<model>_c.h, C99; <model>_c.cpp, its implementation;
#               docs/controllers.md) and adds the STATIC library <target>_c compiled from
#               <model>_c.cpp (C++17, no exceptions, no RTTI): a C program links <target>_c and
#               includes "<model>_c.h". The C++ language must be enabled in the project.
#   OUTPUT_DIR  where the header (and its .md report) go; default
#               ${CMAKE_CURRENT_BINARY_DIR}/weilgen_models/<target>. One directory per target
#               keeps two models of the same machine from sharing an output.
#
# Sets on <target> the properties WEILGEN_MODEL_NAME (e.g. vmc_3axis_o2) and WEILGEN_HEADER
# (full path), and in the caller's scope <target>_MODEL_NAME and <target>_HEADER; with C_API also
# WEILGEN_C_HEADER and <target>_C_HEADER.
#
# Works from the installed package (weilgen::weilgen) and inside the weilgen build tree
# (target weilgen), where the generator is rebuilt before it runs.

# Script mode, run by the custom command after generation: fail with an explanation instead of
# a compiler's "file not found" when the configure-time guess of the model name was wrong.
if(CMAKE_SCRIPT_MODE_FILE AND DEFINED WEILGEN_EXPECTED_HEADER)
  if(NOT EXISTS "${WEILGEN_EXPECTED_HEADER}")
    message(FATAL_ERROR "weilgen did not write ${WEILGEN_EXPECTED_HEADER}: the expected model "
      "name (NAME, or read from the machine file) is not the one weilgen used (see its `wrote` "
      "lines); pass the right NAME <model> to weilgen_add_model()")
  endif()
  return()
endif()

include_guard(GLOBAL)

# This file's path, for the script-mode check above (CMAKE_CURRENT_LIST_FILE changes later).
set(_WEILGEN_ADD_MODEL_FILE "${CMAKE_CURRENT_LIST_FILE}")

# Inside the weilgen tree the shipped machines are in the source dir; the package config sets
# WEILGEN_MACHINES_DIR to the installed copy before including this file.
if(NOT DEFINED WEILGEN_MACHINES_DIR AND DEFINED weilgen_SOURCE_DIR)
  set(WEILGEN_MACHINES_DIR "${weilgen_SOURCE_DIR}/machines")
endif()

function(weilgen_add_model target machine)
  cmake_parse_arguments(PARSE_ARGV 2 ARG "C_API" "ORDER;NAME;OUTPUT_DIR" "")
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "weilgen_add_model: unexpected arguments: ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if(DEFINED ARG_ORDER AND NOT ARG_ORDER MATCHES "^[1-9][0-9]*$")
    message(FATAL_ERROR "weilgen_add_model: ORDER must be a whole number >= 1, got '${ARG_ORDER}'")
  endif()

  # The generator: the imported one from find_package(weilgen), else the one built in this tree.
  if(TARGET weilgen::weilgen)
    set(exe weilgen::weilgen)
  elseif(TARGET weilgen)
    set(exe weilgen)
  else()
    message(FATAL_ERROR "weilgen_add_model: no weilgen executable; call find_package(weilgen)")
  endif()

  # A bare identifier is a shipped machine's name, as on the command line. Resolving it here
  # gives the file to depend on and to read, and does not rely on the directory compiled into
  # the executable (the source tree it was built from).
  if(machine MATCHES "^[A-Za-z_][A-Za-z0-9_]*$" AND NOT EXISTS "${CMAKE_CURRENT_SOURCE_DIR}/${machine}")
    if(NOT EXISTS "${WEILGEN_MACHINES_DIR}/${machine}.yaml")
      message(FATAL_ERROR "weilgen_add_model: no shipped machine '${machine}' in '${WEILGEN_MACHINES_DIR}'")
    endif()
    set(machine "${WEILGEN_MACHINES_DIR}/${machine}.yaml")
  endif()
  cmake_path(ABSOLUTE_PATH machine BASE_DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}" NORMALIZE)
  if(NOT EXISTS "${machine}")
    message(FATAL_ERROR "weilgen_add_model: machine file '${machine}' does not exist")
  endif()

  set(model "${ARG_NAME}")
  if(model STREQUAL "")
    file(STRINGS "${machine}" name_line REGEX "^name:")
    if(NOT name_line MATCHES "^name:[ \t]*[\"']?([A-Za-z_][A-Za-z0-9_]*)")
      message(FATAL_ERROR "weilgen_add_model: no `name: <identifier>` line in '${machine}'; "
        "pass NAME <model>")
    endif()
    set(model "${CMAKE_MATCH_1}")
    if(DEFINED ARG_ORDER)
      file(READ "${machine}" text)
      set(file_order 1)  # the loader's default when the file has no algebra.order
      if(text MATCHES "(^|\n)algebra:[ \t]*{[^}\n]*order:[ \t]*([0-9]+)")
        set(file_order "${CMAKE_MATCH_2}")
      elseif(text MATCHES "(^|\n)algebra:[ \t]*(#[^\n]*)?\n([ \t]+[^\n]*\n)*[ \t]+order:[ \t]*([0-9]+)")
        set(file_order "${CMAKE_MATCH_4}")
      endif()
      if(NOT ARG_ORDER EQUAL file_order)
        string(APPEND model "_o${ARG_ORDER}")
      endif()
    endif()
    # The name comes from the file's contents: re-run the configure step when it changes.
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${machine}")
  endif()

  set(out_dir "${ARG_OUTPUT_DIR}")
  if(out_dir STREQUAL "")
    set(out_dir "${CMAKE_CURRENT_BINARY_DIR}/weilgen_models/${target}")
  endif()
  cmake_path(ABSOLUTE_PATH out_dir BASE_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}" NORMALIZE)
  set(header "${out_dir}/${model}.hpp")

  set(order_args)
  if(DEFINED ARG_ORDER)
    set(order_args --order ${ARG_ORDER})
  endif()
  set(c_api_outputs)
  if(ARG_C_API)
    list(APPEND order_args --c-api)
    set(c_api_outputs "${out_dir}/${model}_c.h" "${out_dir}/${model}_c.cpp")
  endif()
  add_custom_command(
    OUTPUT "${header}" "${out_dir}/${model}.md" ${c_api_outputs}
    COMMAND "$<TARGET_FILE:${exe}>" generate "${machine}" ${order_args} --out "${out_dir}"
    COMMAND "${CMAKE_COMMAND}" "-DWEILGEN_EXPECTED_HEADER=${header}"
            -P "${_WEILGEN_ADD_MODEL_FILE}"
    # The target name makes an in-tree generator build first; TARGET_FILE makes a newer
    # generator (rebuilt or re-installed) regenerate the header.
    DEPENDS "${machine}" ${exe} "$<TARGET_FILE:${exe}>"
    COMMENT "weilgen: generating ${model}.hpp from ${machine}"
    VERBATIM)
  add_custom_target(${target}_generate DEPENDS "${header}")

  add_library(${target} INTERFACE)
  target_include_directories(${target} INTERFACE "${out_dir}")
  # Dependencies of an INTERFACE library reach its consumers: the header exists before they
  # compile.
  add_dependencies(${target} ${target}_generate)
  set_target_properties(${target} PROPERTIES WEILGEN_MODEL_NAME "${model}" WEILGEN_HEADER "${header}")
  set(${target}_MODEL_NAME "${model}" PARENT_SCOPE)
  set(${target}_HEADER "${header}" PARENT_SCOPE)

  if(ARG_C_API)
    # The C API's implementation compiles against the C++ header; it needs no C++ runtime
    # (no exceptions, no RTTI, no allocation), only libm.
    add_library(${target}_c STATIC "${out_dir}/${model}_c.cpp")
    target_link_libraries(${target}_c PUBLIC ${target})
    target_compile_features(${target}_c PRIVATE cxx_std_17)
    if(NOT MSVC)
      target_compile_options(${target}_c PRIVATE -fno-exceptions -fno-rtti)
      target_link_libraries(${target}_c PUBLIC m)
    endif()
    set_target_properties(${target} PROPERTIES WEILGEN_C_HEADER "${out_dir}/${model}_c.h")
    set(${target}_C_HEADER "${out_dir}/${model}_c.h" PARENT_SCOPE)
  endif()
endfunction()
