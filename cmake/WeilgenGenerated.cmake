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
    COMMAND weilgen_codegen generate ${WEILGEN_SHIPPED_MACHINES} --out ${CMAKE_CURRENT_SOURCE_DIR}/generated
    COMMAND ${CMAKE_COMMAND} -E touch ${CMAKE_CURRENT_BINARY_DIR}/generated.stamp
    DEPENDS weilgen_codegen ${WEILGEN_SHIPPED_MACHINES}
    COMMENT "Regenerating generated/ from machines/*.yaml"
    VERBATIM)
  add_custom_target(weilgen_generated ALL DEPENDS ${CMAKE_CURRENT_BINARY_DIR}/generated.stamp)
endif()

# Every committed header must compile standalone with strict flags, as C++17 and as C++20.
if(WEILGEN_BUILD_TESTS)
  file(GLOB WEILGEN_COMMITTED_HEADERS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/generated/*.hpp)
  foreach(header IN LISTS WEILGEN_COMMITTED_HEADERS)
    get_filename_component(model ${header} NAME_WE)
    foreach(std 17 20)
      set(tu ${CMAKE_CURRENT_BINARY_DIR}/header_check/${model}_cxx${std}.cpp)
      if(model MATCHES "_params$")  # identified parameters (weilgen identify --emit-params)
        file(CONFIGURE OUTPUT ${tu} CONTENT
          "// Standalone compile check of generated/${model}.hpp (C++${std}).\n#include \"${model}.hpp\"\n\
template void weilgen_models::${model}::Errors<double>(const std::array<double, weilgen_models::${model}::kNumAxes>&, std::array<double, weilgen_models::${model}::kNumErrors>*);\n\
template void weilgen_models::${model}::Errors<float>(const std::array<float, weilgen_models::${model}::kNumAxes>&, std::array<float, weilgen_models::${model}::kNumErrors>*);\n")
      else()
      file(CONFIGURE OUTPUT ${tu} CONTENT
        "// Standalone compile check of generated/${model}.hpp (C++${std}).\n#include \"${model}.hpp\"\n\
template void weilgen_models::${model}::Deviation<double>(const std::array<double, weilgen_models::${model}::kNumAxes>&, const std::array<double, weilgen_models::${model}::kNumErrors>&, const std::array<double, weilgen_models::${model}::kNumParams>&, std::array<double, 3>*, std::array<double, 3>*);\n\
template void weilgen_models::${model}::Deviation<float>(const std::array<float, weilgen_models::${model}::kNumAxes>&, const std::array<float, weilgen_models::${model}::kNumErrors>&, const std::array<float, weilgen_models::${model}::kNumParams>&, std::array<float, 3>*, std::array<float, 3>*);\n\
template void weilgen_models::${model}::Coefficients<double>(const std::array<double, weilgen_models::${model}::kNumAxes>&, const std::array<double, weilgen_models::${model}::kNumParams>&, std::array<double, 3 * weilgen_models::${model}::kNumErrors>*, std::array<double, 3 * weilgen_models::${model}::kNumErrors>*);\n")
      endif()
      add_library(header_check_${model}_cxx${std} OBJECT ${tu})
      target_include_directories(header_check_${model}_cxx${std} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/generated)
      set_target_properties(header_check_${model}_cxx${std} PROPERTIES CXX_STANDARD ${std} CXX_EXTENSIONS OFF)
      target_compile_options(header_check_${model}_cxx${std} PRIVATE
        -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Werror -fno-exceptions -fno-rtti)
      if(TARGET weilgen_generated)
        add_dependencies(header_check_${model}_cxx${std} weilgen_generated)
      endif()
    endforeach()
  endforeach()
endif()
