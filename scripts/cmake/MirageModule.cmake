# mirage_module(NAME [DEPS targets...] [EXCLUDE folders...])
# One static library per top-level module. Sources are every .cpp under the module folder: a new
# file (or a new render pass folder) joins the build without touching shared CMake files.
# EXCLUDE: sub-folders that are libraries of their own, layered above this one (render/evaluation,
# render/reconstruction).
function(mirage_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;EXCLUDE" ${ARGN})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  # Benchmarks and tools live beside their module but are not part of the library.
  # Matched on the path relative to the module, so a checkout inside a folder named e.g. bench/
  # keeps its sources.
  set(kept "")
  foreach(src IN LISTS sources)
    file(RELATIVE_PATH rel ${CMAKE_CURRENT_SOURCE_DIR} ${src})
    set(excluded FALSE)
    foreach(folder IN LISTS ARG_EXCLUDE)
      if(rel MATCHES "^${folder}/")
        set(excluded TRUE)
      endif()
    endforeach()
    if(NOT rel MATCHES "(^|/)(bench|tools)/" AND NOT excluded)
      list(APPEND kept ${src})
    endif()
  endforeach()
  set(sources ${kept})
  # A module that has no sources yet still builds (a generated empty unit keeps the target valid).
  set(stub ${CMAKE_CURRENT_BINARY_DIR}/${name}_module.cpp)
  if(NOT EXISTS ${stub})
    file(WRITE ${stub} "// generated: keeps ${name} a valid library while it has no sources\n")
  endif()
  add_library(${name} STATIC ${sources} ${stub})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE mirage_warnings)
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()

# mirage_embed_shaders(TARGET DIR NAMESPACE)
# Embeds every GLSL file under DIR (.vert .frag .comp .geom .glsl) into TARGET at build time, so
# the binary runs from any directory. Lookup: mirage::shaders::source("<path relative to DIR>").
# `#include "file.glsl"` lines are resolved at embed time relative to the including file.
function(mirage_embed_shaders target dir)
  file(GLOB_RECURSE shader_files CONFIGURE_DEPENDS
       ${dir}/*.vert ${dir}/*.frag ${dir}/*.comp ${dir}/*.geom ${dir}/*.glsl)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/${target}_shaders.cpp)
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DSHADER_DIR=${dir} -DOUTPUT=${out} -P
            ${PROJECT_SOURCE_DIR}/scripts/cmake/EmbedShaders.cmake
    DEPENDS ${shader_files} ${PROJECT_SOURCE_DIR}/scripts/cmake/EmbedShaders.cmake
    COMMENT "Embedding shaders of ${target}")
  target_sources(${target} PRIVATE ${out})
  set_property(GLOBAL APPEND PROPERTY MIRAGE_SHADER_FILES ${shader_files})
endfunction()
