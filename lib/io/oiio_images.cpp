// The module homcull_oiio.so: the image backend (io/image_backend.hpp) on OpenImageIO, the
// only file of homcull that includes OpenImageIO's headers. Loaded by image_backend() the
// first time an image is written.
#include "io/image_backend.hpp"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <exception>

namespace homcull::detail {
namespace {

OIIO::TypeDesc type_of(PixelType type) {
    switch (type) {
    case PixelType::uint8: return OIIO::TypeDesc::UINT8;
    case PixelType::uint32: return OIIO::TypeDesc::UINT32;
    case PixelType::float32: return OIIO::TypeDesc::FLOAT;
    }
    return OIIO::TypeDesc::UNKNOWN;
}

OIIO::ImageSpec spec_of(const ImagePart& part) {
    OIIO::ImageSpec spec(part.width, part.height, part.channels, type_of(part.type));
    spec.full_x = spec.full_y = 0;
    spec.full_width = part.full_width > 0 ? part.full_width : part.width;
    spec.full_height = part.full_height > 0 ? part.full_height : part.height;
    if (!part.channel_names.empty()) spec.channelnames = part.channel_names;
    for (const auto& [name, value] : part.attributes) spec.attribute(name, value);
    return spec;
}

std::string write(const std::string& path, const ImagePart* parts, std::size_t count, const std::string& format) {
    try {
        if (count == 0) return "no image to write";
        auto out = OIIO::ImageOutput::create(format.empty() ? path : format);
        if (!out) return "cannot write an image of this type (" + OIIO::geterror() + ")";
        if (count > 1 && !out->supports("multiimage"))
            return "the " + std::string(out->format_name()) + " format holds one image, not " + std::to_string(count) + " parts";
        std::vector<OIIO::ImageSpec> specs;
        for (std::size_t i = 0; i < count; ++i) specs.push_back(spec_of(parts[i]));
        for (std::size_t i = 0; i < count; ++i) {
            // The first open declares every part (multi-part EXR writes its headers up front);
            // the others append, in the same order.
            const bool opened = i == 0 ? (count > 1 ? out->open(path, int(count), specs.data()) : out->open(path, specs[0]))
                                       : out->open(path, specs[i], OIIO::ImageOutput::AppendSubimage);
            if (!opened || !out->write_image(type_of(parts[i].type), parts[i].pixels)) {
                const std::string why = out->geterror();
                out->close();
                return why.empty() ? "cannot write part " + std::to_string(i) : why;
            }
        }
        if (!out->close()) return out->geterror();
        return "";
    } catch (const std::exception& e) {
        return e.what();
    }
}

std::string format_for(const std::string& path, std::string* error) {
    try {
        auto out = OIIO::ImageOutput::create(path);
        if (!out) {
            *error = "cannot write an image of this type (" + OIIO::geterror() + ")";
            return "";
        }
        return out->format_name();
    } catch (const std::exception& e) {
        *error = e.what();
        return "";
    }
}

// The canvas as an ImageBuf over its own pixels: drawing changes them in place.
OIIO::ImageBuf wrap(const RgbCanvas& canvas) {
    return OIIO::ImageBuf(OIIO::ImageSpec(canvas.width, canvas.height, 3, OIIO::TypeDesc::UINT8), canvas.pixels);
}

bool render_text(const RgbCanvas& canvas, int x, int y, const std::string& text, int size, const std::string& font, const float rgb[3],
                 bool align_right, std::string* error) {
    try {
        OIIO::ImageBuf image = wrap(canvas);
        const bool ok = OIIO::ImageBufAlgo::render_text(image, x, y, text, size, font, {rgb, 3},
                                                        align_right ? OIIO::ImageBufAlgo::TextAlignX::Right : OIIO::ImageBufAlgo::TextAlignX::Left);
        if (!ok) *error = image.geterror();
        return ok;
    } catch (const std::exception& e) {
        *error = e.what();
        return false;
    }
}

// Lines and boxes are decoration (plots): one that cannot be drawn is left out.
void render_line(const RgbCanvas& canvas, int x0, int y0, int x1, int y1, const float rgb[3]) {
    try {
        OIIO::ImageBuf image = wrap(canvas);
        OIIO::ImageBufAlgo::render_line(image, x0, y0, x1, y1, {rgb, 3});
    } catch (const std::exception&) {
    }
}

void render_box(const RgbCanvas& canvas, int x0, int y0, int x1, int y1, const float rgb[3], bool fill) {
    try {
        OIIO::ImageBuf image = wrap(canvas);
        OIIO::ImageBufAlgo::render_box(image, x0, y0, x1, y1, {rgb, 3}, fill);
    } catch (const std::exception&) {
    }
}

const ImageBackend kBackend = {kImageBackendVersion, &write, &format_for, &render_text, &render_line, &render_box};

}  // namespace
}  // namespace homcull::detail

extern "C" __attribute__((visibility("default"))) const homcull::detail::ImageBackend* homcull_image_backend() {
    return &homcull::detail::kBackend;
}
