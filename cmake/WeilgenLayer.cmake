# weilgen_add_layer(<name> [COLD|TEXT] [DIRS sub...] [DEPENDS lib...] [PRIVATE lib...])
#
# One static library per layer, weilgen_<name> (alias weilgen::<name>), from the layer folder's
# *.cpp (and those of DIRS). Its public headers are <folder>/include/weilgen/<name>/*.hpp and are
# seen only by targets that link it: a layer can include a header of another layer only when it
# lists that layer in DEPENDS, so the compiler enforces the arrows of docs/architecture.md.
# Headers beside the sources are the layer's internals, visible to the layer alone. COLD: no hot
# loop in the layer, compiled with WEILGEN_COLD_OPTIONS (-O2 in Release); TEXT: it only writes
# text, WEILGEN_TEXT_OPTIONS (-O1).
function(weilgen_add_layer name)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "COLD;TEXT" "" "DIRS;DEPENDS;PRIVATE")
  set(globs ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  foreach(dir IN LISTS ARG_DIRS)
    list(APPEND globs ${CMAKE_CURRENT_SOURCE_DIR}/${dir}/*.cpp)
  endforeach()
  file(GLOB sources CONFIGURE_DEPENDS ${globs})
  add_library(weilgen_${name} STATIC ${sources})
  add_library(weilgen::${name} ALIAS weilgen_${name})
  target_include_directories(weilgen_${name}
    PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
  target_link_libraries(weilgen_${name} PUBLIC ${ARG_DEPENDS} PRIVATE ${ARG_PRIVATE})
  target_compile_options(weilgen_${name} PRIVATE ${WEILGEN_WARNINGS})
  if(ARG_COLD)
    target_compile_options(weilgen_${name} PRIVATE ${WEILGEN_COLD_OPTIONS})
  elseif(ARG_TEXT)
    target_compile_options(weilgen_${name} PRIVATE ${WEILGEN_TEXT_OPTIONS})
  endif()
  weilgen_unity(weilgen_${name})
endfunction()

# weilgen_unity(<target>): compile the target's files in batches (WEILGEN_UNITY_BUILD) of equal
# size: n files in ceil(n / WEILGEN_UNITY_BATCH) batches, so that the last batch is not a few files
# beside full ones (the longest batch is what two cores wait for at the end of the build).
function(weilgen_unity target)
  if(WEILGEN_UNITY_BUILD)
    set(size ${WEILGEN_UNITY_BATCH})
    get_target_property(sources ${target} SOURCES)
    list(FILTER sources INCLUDE REGEX "\\.cpp$")
    list(LENGTH sources n)
    if(size GREATER 0 AND n GREATER 0)
      math(EXPR batches "(${n} + ${size} - 1) / ${size}")
      math(EXPR size "(${n} + ${batches} - 1) / ${batches}")
    endif()
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${size})
  endif()
endfunction()
