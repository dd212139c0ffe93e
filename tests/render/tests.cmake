# Render-module extra tests: every embedded GLSL stage validated by glslangValidator (with the
# includes expanded exactly as the renderer compiles them), and the per-pass benchmark.
add_executable(mirage_dump_shaders ${CMAKE_CURRENT_LIST_DIR}/DumpShaders.cpp)
target_link_libraries(mirage_dump_shaders PRIVATE mirage_render mirage_warnings)
if(GLSLANG_VALIDATOR)
  add_test(NAME render.glslang_validate
           COMMAND ${CMAKE_COMMAND} -DDUMP=$<TARGET_FILE:mirage_dump_shaders>
                   -DVALIDATOR=${GLSLANG_VALIDATOR} -DOUT=${CMAKE_CURRENT_BINARY_DIR}/glsl_dump
                   -P ${CMAKE_CURRENT_LIST_DIR}/ValidateShaders.cmake)
else()
  # Fails loudly rather than silently skipping: install glslang-tools (scripts/install-deps.sh).
  add_test(NAME render.glslang_validate
           COMMAND ${CMAKE_COMMAND} -E echo "glslangValidator not found: apt-get install glslang-tools")
  set_tests_properties(render.glslang_validate PROPERTIES WILL_FAIL FALSE PASS_REGULAR_EXPRESSION "^$")
endif()
set_tests_properties(render.glslang_validate PROPERTIES LABELS render)
if(MIRAGE_BUILD_BENCHMARKS AND EXISTS ${PROJECT_SOURCE_DIR}/render/bench/CMakeLists.txt)
  add_subdirectory(${PROJECT_SOURCE_DIR}/render/bench ${CMAKE_BINARY_DIR}/render/bench)
endif()
