#include "io/legend_font.hpp"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

namespace homcull::detail {

const LegendFont& legend_font() {
    static const LegendFont font = [] {
        LegendFont f;
        for (const char* name : {"DejaVuSans", ""}) {
            OIIO::ImageBuf probe(OIIO::ImageSpec(64, 24, 3, OIIO::TypeDesc::UINT8));
            if (OIIO::ImageBufAlgo::render_text(probe, 2, 16, "0.5", 13, name)) {
                f.found = true;
                f.name = name;
                return f;
            }
            f.reason += std::string(*name ? name : "OIIO's default font") + ": " + probe.geterror() + "; ";
        }
        f.reason = "no TrueType font could be rendered (" + f.reason.substr(0, f.reason.size() - 2) +
                   "); install fonts-dejavu-core for the legend text";
        return f;
    }();
    return font;
}

}  // namespace homcull::detail
