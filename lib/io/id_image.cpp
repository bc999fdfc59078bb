#include <homcull/error.hpp>
#include <homcull/io/id_image.hpp>

#include "io/image_backend.hpp"

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
    detail::write_rgb_pixels(path, width, height, rgb.data(), "");
}

void write_id_image(const std::string& path, int width, int height, const std::vector<std::uint32_t>& ids) {
    if (width < 1 || height < 1 || ids.size() != std::size_t(width) * std::size_t(height))
        throw Error(path + ": id buffer does not match the image size");
    const detail::ImageBackend& images = detail::image_backend();
    std::string why;
    const std::string format = images.format_for(path, &why);
    if (format.empty()) throw Error(path + ": " + why);
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
    detail::ImagePart image;
    image.width = width;
    image.height = height;
    image.channels = 1;
    image.type = detail::PixelType::uint32;
    image.pixels = stored.data();
    image.channel_names = {"id"};
    image.attributes = {{"homcull:id_encoding", "object id + 1, 0 = no object"}};
    why = images.write(path, &image, 1, "");
    if (!why.empty()) throw Error(path + ": " + why);
}

}  // namespace homcull
