# The reconstruction of real proxies and lights (render/reconstruction/): its own executable, as
# it needs mirage_reconstruction (and Open3D) beside mirage_render.
file(GLOB reconstruction_tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/*_test.cpp)
add_executable(mirage_reconstruction_tests ${reconstruction_tests})
target_link_libraries(mirage_reconstruction_tests PRIVATE mirage_reconstruction mirage_render
                      mirage_core mirage_test_support GTest::gtest_main
                      mirage_warnings)
add_dependencies(mirage_reconstruction_tests mirage)
gtest_discover_tests(mirage_reconstruction_tests DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60
                     PROPERTIES LABELS reconstruction TIMEOUT 600)
