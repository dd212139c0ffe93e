// tinygltf and stb_image compiled from the Debian headers into the fuzz executables, only in
// sanitizer/libFuzzer builds: Debian's libtinygltf.so and libstb.so are not instrumented, so
// AddressSanitizer could not see an out-of-bounds read inside them, and libFuzzer could not
// steer by their coverage. Definitions in the executable take precedence over the shared
// libraries', so mirage_core's calls land here. Same header version as the shared library.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image.h>
#include <stb_image_write.h>
#include <tiny_gltf.h>
