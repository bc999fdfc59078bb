#include "exr_parts.hpp"

#include <homcull/error.hpp>

#include <OpenImageIO/imageio.h>

namespace homcull::test {

std::vector<ExrPart> read_exr_parts(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(path + ": " + OIIO::geterror());
    std::vector<ExrPart> parts;
    for (int i = 0; in->seek_subimage(i, 0); ++i) {
        const OIIO::ImageSpec& spec = in->spec();
        ExrPart p{spec.get_string_attribute("oiio:subimagename"), spec.width, spec.height, spec.nchannels,
                  spec.format == OIIO::TypeDesc::FLOAT, {}};
        p.values.resize(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
        if (!in->read_image(i, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, p.values.data())) throw Error(path + ": " + in->geterror());
        parts.push_back(std::move(p));
    }
    return parts;
}

}  // namespace homcull::test
