// The fuzz build compiles the same stb_image.h that Debian's libstb is built from into
// the image target, so that the decoder is instrumented (coverage feedback, ASan/UBSan).
// Its definitions take precedence over libstb.so's. The normal build uses libstb.
#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>
