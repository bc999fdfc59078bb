#include "io/legend_font.hpp"

#include "io/image_backend.hpp"

#include <cstdint>
#include <vector>

namespace homcull::detail {

const LegendFont& legend_font() {
    static const LegendFont font = [] {
        const ImageBackend& images = image_backend();
        LegendFont f;
        for (const char* name : {"DejaVuSans", ""}) {
            std::vector<std::uint8_t> pixels(64 * 24 * 3);
            const float white[3] = {1.0f, 1.0f, 1.0f};
            std::string why;
            if (images.render_text(RgbCanvas{64, 24, pixels.data()}, 2, 16, "0.5", 13, name, white, false, &why)) {
                f.found = true;
                f.name = name;
                return f;
            }
            f.reason += std::string(*name ? name : "OIIO's default font") + ": " + why + "; ";
        }
        f.reason = "no TrueType font could be rendered (" + f.reason.substr(0, f.reason.size() - 2) +
                   "); install fonts-dejavu-core for the legend text";
        return f;
    }();
    return font;
}

}  // namespace homcull::detail
