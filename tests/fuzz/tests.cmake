# Fuzzing of every loader (docs/development.md, "Fuzzing"; the glTF loader: docs/scene.md).
#  - <target>: <Target>Fuzz.cpp + the time-boxed mutation driver FuzzDriver.cpp (works with gcc);
#    ctest runs each for MIRAGE_FUZZ_SECONDS (glTF) or MIRAGE_LOADER_FUZZ_SECONDS (the others)
#    with a fixed seed over its seed corpus (tests/fuzz/corpus/<format> and test data).
#  - <target>_libfuzzer (-DMIRAGE_LIBFUZZER=ON, clang only): coverage-guided libFuzzer builds.
# Included from tests/CMakeLists.txt, so CMAKE_CURRENT_SOURCE_DIR is tests/.
set(MIRAGE_FUZZ_SECONDS 20 CACHE STRING "Seconds the scene loader fuzz test runs under ctest")
set(MIRAGE_LOADER_FUZZ_SECONDS 8 CACHE STRING "Seconds each other loader's fuzz test runs under ctest")
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

add_executable(scene_loader_fuzz ${_fuzz_dir}/SceneLoaderFuzz.cpp ${_fuzz_dir}/FuzzDriver.cpp
                                 ${_fuzz_dir}/FuzzSupport.cpp)
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
  add_executable(scene_loader_libfuzzer ${_fuzz_dir}/SceneLoaderFuzz.cpp ${_fuzz_dir}/FuzzSupport.cpp)
  mirage_scene_fuzz_target(scene_loader_libfuzzer)
  target_compile_options(scene_loader_libfuzzer PRIVATE -fsanitize=fuzzer ${_shim})
  target_link_options(scene_loader_libfuzzer PRIVATE -fsanitize=fuzzer)
endif()

# The other loaders: one executable and one time-boxed ctest each.
#   mirage_loader_fuzz(NAME SOURCE LIBS CORPUS_DIR...)
set(_corpus ${_fuzz_dir}/corpus)
function(mirage_loader_fuzz name source libs)
  set(corpus_args)
  foreach(dir IN LISTS ARGN)
    list(APPEND corpus_args --corpus ${dir})
  endforeach()
  set(variants ${name})
  if(MIRAGE_LIBFUZZER)
    list(APPEND variants ${name}_libfuzzer)
  endif()
  foreach(exe IN LISTS variants)
    if(exe MATCHES "_libfuzzer$")
      add_executable(${exe} ${_fuzz_dir}/${source} ${_fuzz_dir}/FuzzSupport.cpp)
      target_compile_options(${exe} PRIVATE -fsanitize=fuzzer ${_shim})
      target_link_options(${exe} PRIVATE -fsanitize=fuzzer)
    else()
      add_executable(${exe} ${_fuzz_dir}/${source} ${_fuzz_dir}/FuzzDriver.cpp
                            ${_fuzz_dir}/FuzzSupport.cpp)
      target_link_libraries(${exe} PRIVATE mirage_warnings)
    endif()
    target_include_directories(${exe} PRIVATE ${PROJECT_SOURCE_DIR})
    target_link_libraries(${exe} PRIVATE ${libs})
    target_compile_definitions(${exe} PRIVATE MIRAGE_FUZZ_CORPUS_DIR="${_corpus}")
  endforeach()
  add_test(NAME ${name}
           COMMAND ${name} --seconds ${MIRAGE_LOADER_FUZZ_SECONDS} --seed 1 ${corpus_args}
                   --crash-dir ${CMAKE_CURRENT_BINARY_DIR}/output/fuzz)
  math(EXPR timeout "${MIRAGE_LOADER_FUZZ_SECONDS} * 3 + 60")
  set_tests_properties(${name} PROPERTIES LABELS "fuzz" TIMEOUT ${timeout})
endfunction()

mirage_loader_fuzz(calibration_fuzz CalibrationFuzz.cpp mirage_core
                   ${CMAKE_CURRENT_SOURCE_DIR}/data/calib ${CMAKE_CURRENT_SOURCE_DIR}/data/calib/bad)
mirage_loader_fuzz(board_fuzz BoardFuzz.cpp "mirage_tracking;mirage_core"
                   ${PROJECT_SOURCE_DIR}/data/boards ${_corpus}/board)
mirage_loader_fuzz(session_fuzz SessionFuzz.cpp mirage_core ${_corpus}/session)
mirage_loader_fuzz(poses_csv_fuzz PosesCsvFuzz.cpp mirage_core ${_corpus}/poses)
mirage_loader_fuzz(matroska_fuzz MatroskaFuzz.cpp mirage_core ${_corpus}/matroska)
mirage_loader_fuzz(avi_fuzz AviFuzz.cpp mirage_core ${_corpus}/avi)
mirage_loader_fuzz(env_image_fuzz EnvImageFuzz.cpp mirage_core ${_corpus}/envimage
                   ${CMAKE_CURRENT_SOURCE_DIR}/data/scenes/good)
mirage_loader_fuzz(density_grid_fuzz DensityGridFuzz.cpp mirage_core ${_corpus}/density
                   ${CMAKE_CURRENT_SOURCE_DIR}/data/scenes/good)
