// Float RGB images and their file formats. 8-bit outputs (PNG, PPM, BMP) store a display
// encoding of the linear values (ToneMap: clamped as the course renderer did, the sRGB
// curve, or a filmic curve then sRGB); EXR keeps linear floats. Every write is atomic
// (temporary file, then rename).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/enum_names.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/math.h"

namespace lc::io {

struct Image {
  int width = 0, height = 0;
  std::vector<Color> pixels;  // row-major, top row first

  Image() = default;
  Image(int w, int h) : width(w), height(h), pixels(size_t(w) * size_t(h)) {}
  Color& at(int x, int y) { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
  const Color& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
};

// How a linear value v becomes an 8-bit one (after scaling by 2^exposure):
//   Clamp:  round(clamp(v, 0, 1) * 255), the course renderer's look (values stored as they are);
//   Srgb:   the sRGB OETF of clamp(v, 0, 1), what a display expects of a linear image;
//   Filmic: Narkowicz's fit of the ACES filmic curve applied to 0.6 v (highlights roll off
//           instead of clipping), then the sRGB OETF.
enum class ToneMap { Clamp, Srgb, Filmic };
// Its names (core/enum_names.h), in the order render --tonemap's help lists them.
inline constexpr EnumName<ToneMap> kToneMapNames[] = {
    {ToneMap::Srgb, "srgb", "the linear image sRGB-encoded for display"},
    {ToneMap::Filmic, "filmic", "highlights roll off: Narkowicz's ACES fit, then sRGB"},
    {ToneMap::Clamp, "clamp",
     "values stored as they are, the course renderer's look; sRGB textures not linearised"}};

using TextMetadata = std::vector<std::pair<std::string, std::string>>;  // (key, value)

// What writeImage stores besides the pixels.
struct WriteOptions {
  ToneMap tonemap = ToneMap::Clamp;
  float exposure = 0;  // 8-bit outputs: linear values are scaled by 2^exposure first
  // Text metadata, (key, value): EXR string attributes, PNG tEXt chunks (iTXt when the
  // value is not ASCII); PPM and BMP have no place for it. Keys are 1..79 printable ASCII
  // characters.
  TextMetadata metadata;
  // EXR only: more float channels beside R, G, B, each width x height values, row-major,
  // named as OpenEXR layers are ("albedo.R", "depth.Z"); the main image stays R, G, B, so
  // readers that know nothing of layers read it as before. Other formats refuse them.
  struct Channel {
    std::string name;
    std::vector<float> values;
  };
  std::vector<Channel> channels;
  // EXR only: threads compressing its blocks of lines (0: one per core). The file's bytes
  // are the same for any count; a 1920x1080 image took 0.7 s on one thread, 0.35 s on two.
  int threads = 0;
};

// Writes by extension: .png .ppm .bmp (8-bit) or .exr (float). Throws lc::Error
// (unknown extension, unwritable path) and leaves any existing file untouched on failure.
// 8-bit: quantize8 of each channel. EXR stores 32-bit float RGB (exact round trip):
// tonemap and exposure are ignored. NaN channels are written as 0 in every format.
void writeImage(const std::string& path, const Image& image, const WriteOptions& options);
inline void writeImage(const std::string& path, const Image& image, ToneMap tonemap = ToneMap::Clamp) {
  WriteOptions o;
  o.tonemap = tonemap;
  writeImage(path, image, o);
}

// What went wrong in readImage, so that callers (textures) can reword the message and
// add the location that referred to the file.
class ImageReadError : public Error {
 public:
  // Memory: the pixels would not fit in --max-memory (core/memory_budget.h); what() says so.
  enum class Kind { Open, Decode, TooLarge, Memory };
  ImageReadError(Kind kind, const std::string& path, const std::string& reason,
                 const std::string& msg, int width = 0, int height = 0)
      : Error(msg), kind(kind), path(path), reason(reason), width(width), height(height) {}
  Kind kind;
  std::string path;
  std::string reason;     // strerror, or the decoder's message (libpng, libjpeg, stb, OpenEXR)
  int width, height;      // the image size, for Kind::TooLarge
};

// Reads by content, not extension: EXR (OpenEXR) as linear floats, PNG with libpng, JPEG with
// libjpeg-turbo, BMP, TGA, PNM and Radiance HDR with stb_image (docs/ERRORS.md, "Image
// decoders"). 8-bit values become value/255 (linearised when srgb = true); 16-bit PNG and
// PNM value/65535 (maxval); .hdr stays linear. Grey and palette images expand to RGB, alpha
// is dropped, CMYK JPEG is converted as stb_image did. The size is checked against maxPixels
// from the header, before the pixels are decoded. Throws ImageReadError:
//   "cannot open 'path': No such file or directory"
//   "cannot read image 'path': <decoder's reason>"
//   "image 'path' is WxH = N pixels, more than the limit of M"
Image readImage(const std::string& path, bool srgb = false,
                uint64_t maxPixels = Limits{}.maxTexturePixels);

// One float channel of an EXR file by name ("depth.Z"), width x height values row-major
// (width and height are set). Throws ImageReadError when the file or the channel is missing.
std::vector<float> readExrChannel(const std::string& path, const std::string& name, int& width, int& height);

// sRGB transfer functions on [0,1] (values outside are clamped).
float srgbToLinear(float v);
float linearToSrgb(float v);

// The 8-bit value writeImage stores for a linear channel value (scale = 2^exposure).
uint8_t quantize8(float v, ToneMap tonemap, float scale = 1);

// ToneMap by name (kToneMapNames) and back; parse throws lc::Error on others.
inline ToneMap parseToneMap(std::string_view name) { return parseEnum(kToneMapNames, name, "tone map"); }
inline const char* toneMapName(ToneMap tonemap) { return enumName(kToneMapNames, tonemap); }

// True for extensions writeImage accepts.
bool isWritableImageExtension(const std::string& ext);

}  // namespace lc::io
