#pragma once
// Writes a per-sample object id buffer as an image with OpenImageIO.
#include <homcull/scene.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace homcull {

// 8-bit formats (.png, .jpg, .bmp, ...) get a colour per object (a hash of the id, black
// where nothing is hit), for looking at. Other formats (.exr, .tif) get one uint32 channel
// "id" holding object id + 1, and 0 where nothing is hit, for tools to read back.
void write_id_image(const std::string& path, int width, int height,
                    const std::vector<std::uint32_t>& ids);

// Writes 8-bit RGB pixels (3 bytes each, rows top to bottom) in the format the extension
// names. Throws homcull::Error naming the file.
void write_rgb_image(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb);

// The colour write_id_image gives an object id, as 0xRRGGBB.
std::uint32_t id_color(std::uint32_t id);

}  // namespace homcull
