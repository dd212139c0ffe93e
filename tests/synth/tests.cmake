# Synthetic-session checks: the shipped sample session's ground truth against the tags
# the tracking module detects in its frames. Own executable: it needs mirage_tracking next to
# mirage_render, which the per-module test executables do not link together.
file(GLOB synth_tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/*_test.cpp)
add_executable(mirage_synth_tests ${synth_tests})
target_link_libraries(mirage_synth_tests PRIVATE mirage_render mirage_tracking mirage_core mirage_test_support
                      GTest::gtest_main mirage_warnings)
add_dependencies(mirage_synth_tests mirage)
gtest_discover_tests(mirage_synth_tests DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60
                     PROPERTIES LABELS synth TIMEOUT 600)
