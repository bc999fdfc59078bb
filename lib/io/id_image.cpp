#include <homcull/error.hpp>
#include <homcull/io/id_image.hpp>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace homcull {

std::uint32_t id_color(std::uint32_t id) {
    // A 32-bit integer hash (Wellons' "lowbias32") so that neighbouring ids differ in colour;
    // kept away from black, which means "nothing".
    std::uint32_t x = id + 1;
    x ^= x >> 16; x *= 0x7feb352du;
    x ^= x >> 15; x *= 0x846ca68bu;
    x ^= x >> 16;
    return x | 0x404040u;
}

void write_rgb_image(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb) {
    if (width < 1 || height < 1 || rgb.size() != 3 * std::size_t(width) * std::size_t(height))
        throw Error(path + ": pixel buffer does not match the image size");
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw Error(path + ": cannot write an image of this type (" + OIIO::geterror() + ")");
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgb.data()) || !out->close())
        throw Error(path + ": " + out->geterror());
}

void write_id_image(const std::string& path, int width, int height, const std::vector<std::uint32_t>& ids) {
    if (width < 1 || height < 1 || ids.size() != std::size_t(width) * std::size_t(height))
        throw Error(path + ": id buffer does not match the image size");
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw Error(path + ": cannot write an image of this type (" + OIIO::geterror() + ")");
    std::string format = out->format_name();
    const bool eight_bit = format == "png" || format == "jpeg" || format == "bmp" || format == "targa" ||
                           format == "gif" || format == "webp" || format == "pnm";
    if (eight_bit) {
        std::vector<std::uint8_t> rgb(ids.size() * 3);
        for (std::size_t i = 0; i < ids.size(); ++i) {
            const std::uint32_t c = ids[i] == kNoObject ? 0u : id_color(ids[i]);
            rgb[3 * i + 0] = std::uint8_t((c >> 16) & 0xFF);
            rgb[3 * i + 1] = std::uint8_t((c >> 8) & 0xFF);
            rgb[3 * i + 2] = std::uint8_t(c & 0xFF);
        }
        write_rgb_image(path, width, height, rgb);
        return;
    }
    std::vector<std::uint32_t> stored(ids.size());
    std::transform(ids.begin(), ids.end(), stored.begin(), [](std::uint32_t id) { return id == kNoObject ? 0u : id + 1; });
    OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::UINT32);
    spec.channelnames = {"id"};
    spec.attribute("homcull:id_encoding", "object id + 1, 0 = no object");
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT32, stored.data()) || !out->close())
        throw Error(path + ": " + out->geterror());
}

}  // namespace homcull
