#pragma once
// Debug dumps of one frame's occlusion buffer and hierarchical occlusion maps (issue 6):
// a multi-part OpenEXR file with every buffer and pyramid level at full float precision, and
// PNG companions with a perceptual colormap and a legend that states the value range.
//
// Parts, in file order (dump_parts()):
//   buffer.coverage   per buffer sample: 1 covered by an occluder, 0 not
//   buffer.depth      per buffer sample: conservative occluder depth as clip w (larger is
//                     farther), +inf where no occluder is known (OcclusionBuffer::read_depth)
//   opacity.L<k>      per cell of level k: covered samples / samples (OcclusionMaps::opacity)
//   maxz.L<k>         per cell of level k: farthest depth of its covered samples (the hzb
//                     pyramid, OcclusionMaps::farthest_depth) as 1/w, larger is nearer
//   nbz.L<k>          per cell of level k: the no-background Z-buffer pyramid
//                     (OcclusionMaps::nearest_depth) as 1/w, larger is nearer
//   deb               the depth estimation buffer as 1/w, only when the maps use it
//                     (OcclusionMapsConfig::depth == DepthTest::deb; otherwise it is never
//                     filled)
// for k = 0 .. maps.levels() - 1: 2 + 3 * levels parts, plus one with the deb. Every value is
// the library's own float, unconverted, so a dump compares bit for bit with the accessors;
// +inf means "no occluder" in every depth part. All parts share the EXR display window (the
// largest part's size, which OpenEXR requires of multi-part files); each part's data window
// is its own size at the origin.
#include <homcull/occlusion_buffer.hpp>
#include <homcull/occlusion_maps.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace homcull {

enum class DumpColormap : std::uint8_t {
    viridis,  // coverage and opacity, over the fixed range [0, 1]
    magma,    // depths, over the range of their finite values, nearer drawn brighter
};

struct DumpPart {
    std::string name;      // EXR part name and PNG file stem: buffer.coverage, opacity.L0, ...
    std::string quantity;  // what a value means, with its unit (stored as homcull:quantity)
    int width = 0, height = 0;
    std::vector<float> values;  // row-major, top row first
    DumpColormap colormap = DumpColormap::viridis;
    bool larger_is_nearer = false;  // depth parts: 1/w (true) or w (false); drawn near = bright
};

// The parts of a dump, in file order (see above). The maps must have been built from `buffer`,
// unchanged since: a depth pyramid the maps do not make (OcclusionMapsConfig::depth_pyramids)
// is built here from `buffer`.
std::vector<DumpPart> dump_parts(const OcclusionBuffer& buffer, const OcclusionMaps& maps);

// Writes every part into one multi-part OpenEXR file (FLOAT channel "Y", zip compression). The
// first part's header also lists every part's name ("homcull:parts"), which plain
// `oiiotool --info -v` prints (it shows the first part's metadata only; `-a` shows each part's).
// Throws homcull::Error naming the file when it cannot be written.
void write_maps_exr(const OcclusionBuffer& buffer, const OcclusionMaps& maps, const std::string& path);
void write_maps_exr(const std::vector<DumpPart>& parts, const std::string& path);

// What write_colormap_png wrote.
struct ColormapPng {
    std::string path;
    int width = 0, height = 0;  // the PNG: the part scaled up by `scale`, plus the legend strip
    int scale = 1;              // nearest-neighbour magnification of each cell
    // The range the colours span: [0, 1] for viridis parts, the finite values' range for
    // depth parts (finite = false when the part has none: every pixel is "no occluder").
    double range_min = 0.0, range_max = 0.0;
    bool finite = true;
    std::uint64_t no_occluder = 0;  // pixels with an infinite depth, drawn in kNoOccluderRgb
    bool text_drawn = false;        // the legend's text could be rendered (a font was found)
    std::string note;               // why not, when text_drawn is false
};

// Height of the legend strip below the picture, and the least PNG width (small pyramid levels
// are magnified by an integer factor until the legend's text fits).
inline constexpr int kLegendHeight = 48;
inline constexpr int kMinPngWidth = 384;
// "No occluder" (an infinite depth): a green no magma colour comes near.
inline constexpr std::uint8_t kNoOccluderRgb[3] = {0, 200, 90};

// The PNG size for a part of width x height cells: scale = ceil(kMinPngWidth / width) (at
// least 1), width * scale by height * scale + kLegendHeight.
ColormapPng colormap_png_size(int width, int height);

// One part as an 8-bit RGB PNG with its colormap and a legend strip below it: a colour bar,
// the range at its ends and, for depth parts, how many pixels have no occluder. The legend's
// text needs a TrueType font (DejaVu Sans, Debian's fonts-dejavu-core, else OIIO's default);
// without one the bar is still drawn and the result says why the text is missing.
// Throws homcull::Error naming the file when it cannot be written.
ColormapPng write_colormap_png(const DumpPart& part, const std::string& path);

// Every part of dump_parts() as DIR/<part name>.png, and DIR/colormaps.json listing each
// PNG with its range, its no-occluder count and whether the legend text was drawn (the range
// "beside" the image when no font could be found). DIR must exist.
std::vector<ColormapPng> write_colormap_pngs(const std::vector<DumpPart>& parts, const std::string& dir);

}  // namespace homcull
