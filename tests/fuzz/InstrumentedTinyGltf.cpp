// tinygltf compiled from the Debian header into the fuzz executables, only in sanitizer/libFuzzer
// builds: Debian's libtinygltf.so is not instrumented, so AddressSanitizer could not see an
// out-of-bounds access inside it and libFuzzer could not steer by its coverage. Definitions in
// the executable take precedence over the shared library's, so mirage_core's calls land here.
// Same header version as the shared library. mirage decodes images itself (OpenCV), so
// tinygltf's stb_image paths are left out.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#include <tiny_gltf.h>
