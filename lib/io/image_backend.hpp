#pragma once
// Every call homcull makes into OpenImageIO goes through this table, which the module
// homcull_oiio.so (io/oiio_images.cpp) fills. The module is loaded the first time an image is
// written (image_backend()), not when a program starts: OpenImageIO 2.4 as Debian 12 ships it
// pulls in about 260 shared libraries (codecs, DICOM, OpenCV, ...), which took 0.4 s of every
// start of the homcull program and of every test process, for the few that write an image.
//
// The module and the libraries that call it come from one build (the same compiler and
// standard library), so the table passes C++ types; kImageBackendVersion tells a module of
// another build apart. No exception crosses the table: the module reports failures as text.
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace homcull::detail {

// Raised whenever anything below changes: a module of another build is refused, not misread.
inline constexpr std::uint32_t kImageBackendVersion = 1;
// The function the module exports, returning its table.
inline constexpr const char* kImageBackendEntry = "homcull_image_backend";
// The module's file name, in the build tree and in <libdir>/homcull when installed.
inline constexpr const char* kImageModuleName = "homcull_oiio.so";
// Environment variable naming the module's path, tried instead of the usual places.
inline constexpr const char* kImageModuleVariable = "HOMCULL_IMAGE_MODULE";

enum class PixelType : std::uint8_t { uint8, uint32, float32 };

// One image to write, or one part of a multi-part file.
struct ImagePart {
    int width = 0, height = 0, channels = 0;
    PixelType type = PixelType::uint8;
    const void* pixels = nullptr;  // rows top to bottom, channels interleaved
    std::vector<std::string> channel_names;  // empty: the format's own (R, G, B, ...)
    std::vector<std::pair<std::string, std::string>> attributes;  // metadata, as text
    int full_width = 0, full_height = 0;  // the display window at the origin; 0: the image's own
};

// 8-bit RGB pixels, rows top to bottom, that the drawing calls change in place.
struct RgbCanvas {
    int width = 0, height = 0;
    std::uint8_t* pixels = nullptr;
};

struct ImageBackend {
    std::uint32_t version;
    // Writes the parts to `path` as one file, a multi-part file when there are several (the
    // format must hold them); `format` names the format, or is empty to take it from the file
    // name. Returns "" or why it could not, without the path.
    std::string (*write)(const std::string& path, const ImagePart* parts, std::size_t count, const std::string& format);
    // The format the file name selects ("png", "openexr", ...); "" and why in *error when none.
    std::string (*format_for)(const std::string& path, std::string* error);
    // Draws text with its baseline starting at (x, y), or ending there when align_right, in the
    // TrueType font `font` ("" OpenImageIO's default) of `size` pixels. False and why in
    // *error when the font cannot be rendered.
    bool (*render_text)(const RgbCanvas& canvas, int x, int y, const std::string& text, int size, const std::string& font,
                        const float rgb[3], bool align_right, std::string* error);
    void (*render_line)(const RgbCanvas& canvas, int x0, int y0, int x1, int y1, const float rgb[3]);
    void (*render_box)(const RgbCanvas& canvas, int x0, int y0, int x1, int y1, const float rgb[3], bool fill);
};

// The module's table, loaded on the first call that succeeds (thread-safe). Throws
// homcull::Error naming every place tried and why each failed when it cannot be loaded; the next
// call looks again. Looks, in order, at $HOMCULL_IMAGE_MODULE alone when it is set; else
// <the program's folder>/../<libdir>/homcull
// (an installed program), the library search path (the RUNPATH that homcull::io gives the
// programs linking an installed package, LD_LIBRARY_PATH, ...), and the build tree's module.
const ImageBackend& image_backend();

// Writes one 8-bit RGB image of width x height pixels (rows top first) through the module, in
// `format` (an OpenImageIO format name) or, given "", the one the file's extension names.
// Throws homcull::Error naming the file and why when it cannot.
void write_rgb_pixels(const std::string& path, int width, int height, const std::uint8_t* rgb, const char* format);

}  // namespace homcull::detail
