// tinyobjloader's implementation compiled into the fuzz target, so the
// sanitizers and the coverage instrumentation see inside it too (the main
// build links Debian's prebuilt library instead).
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
