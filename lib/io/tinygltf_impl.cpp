// tinygltf's implementation, compiled here from Debian's header rather than linked from
// Debian's libtinygltf.so: that library was built with other configuration macros than its
// header shows, so TinyGLTF's members sit at other offsets (its loader then finds its file
// callbacks unset). Compiling it with the settings below keeps header and code in step.
// No image codecs: occlusion needs positions only.
#define TINYGLTF_IMPLEMENTATION
#include "io/tinygltf_config.hpp"
