# Fuzzing of the glTF scene loader (docs/scene.md, "Fuzzing").
#  - scene_loader_fuzz: SceneLoaderFuzz.cpp + a time-boxed mutation driver (works with gcc);
#    ctest runs it for MIRAGE_FUZZ_SECONDS with a fixed seed over the test scenes.
#  - scene_loader_libfuzzer (-DMIRAGE_LIBFUZZER=ON, clang only): coverage-guided libFuzzer build.
# Included from tests/CMakeLists.txt, so CMAKE_CURRENT_SOURCE_DIR is tests/.
set(MIRAGE_FUZZ_SECONDS 20 CACHE STRING "Seconds the scene loader fuzz test runs under ctest")
option(MIRAGE_LIBFUZZER "Build the clang libFuzzer target scene_loader_libfuzzer" OFF)

set(_fuzz_dir ${CMAKE_CURRENT_LIST_DIR})
set(_scene_data ${CMAKE_CURRENT_SOURCE_DIR}/data/scenes)

function(mirage_scene_fuzz_target target)
  target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR})
  target_link_libraries(${target} PRIVATE mirage_core)
  target_compile_definitions(${target} PRIVATE MIRAGE_FUZZ_BASE_DIR="${_scene_data}/good")
  # Under sanitizers, compile tinygltf into the executable so they are instrumented.
  if(MIRAGE_SANITIZE OR MIRAGE_LIBFUZZER)
    target_sources(${target} PRIVATE ${_fuzz_dir}/InstrumentedTinyGltf.cpp)
    set_source_files_properties(${_fuzz_dir}/InstrumentedTinyGltf.cpp PROPERTIES COMPILE_OPTIONS "-w")
    target_link_libraries(${target} PRIVATE nlohmann_json::nlohmann_json)
  endif()
endfunction()

add_executable(scene_loader_fuzz ${_fuzz_dir}/SceneLoaderFuzz.cpp ${_fuzz_dir}/FuzzDriver.cpp)
mirage_scene_fuzz_target(scene_loader_fuzz)
target_link_libraries(scene_loader_fuzz PRIVATE mirage_warnings)
file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/output/fuzz)
add_test(NAME scene_loader_fuzz
         COMMAND scene_loader_fuzz --seconds ${MIRAGE_FUZZ_SECONDS} --seed 1
                 --corpus ${_scene_data}/good --corpus ${_scene_data}/bad
                 --crash-dir ${CMAKE_CURRENT_BINARY_DIR}/output/fuzz)
math(EXPR _fuzz_timeout "${MIRAGE_FUZZ_SECONDS} * 3 + 60")
set_tests_properties(scene_loader_fuzz PROPERTIES LABELS "core;fuzz" TIMEOUT ${_fuzz_timeout})

if(MIRAGE_LIBFUZZER)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "MIRAGE_LIBFUZZER needs clang (e.g. CXX=clang++ CC=clang); libFuzzer is clang's")
  endif()
  # Coverage instrumentation for the code under test; the fuzz executable links libFuzzer's main.
  target_compile_options(mirage_core PRIVATE -fsanitize=fuzzer-no-link)
  # Debian 12's clang 14 lacks what libstdc++ 12 needs for std::source_location (core/Error.h).
  if(CMAKE_CXX_COMPILER_VERSION VERSION_LESS 15)
    set(_shim "SHELL:-include ${_fuzz_dir}/SourceLocationShim.h")
    target_compile_options(mirage_core PRIVATE ${_shim})
  endif()
  add_executable(scene_loader_libfuzzer ${_fuzz_dir}/SceneLoaderFuzz.cpp)
  mirage_scene_fuzz_target(scene_loader_libfuzzer)
  target_compile_options(scene_loader_libfuzzer PRIVATE -fsanitize=fuzzer ${_shim})
  target_link_options(scene_loader_libfuzzer PRIVATE -fsanitize=fuzzer)
endif()
