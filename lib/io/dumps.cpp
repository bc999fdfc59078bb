#include <homcull/error.hpp>
#include <homcull/io/dumps.hpp>
#include <homcull/io/write_file.hpp>

#include "io/image_backend.hpp"
#include "io/legend_font.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>

namespace homcull {
namespace {

DumpPart make_part(std::string name, std::string quantity, int width, int height, DumpColormap colormap, bool larger_is_nearer) {
    DumpPart p;
    p.name = std::move(name);
    p.quantity = std::move(quantity);
    p.width = width;
    p.height = height;
    p.values.reserve(std::size_t(width) * std::size_t(height));
    p.colormap = colormap;
    p.larger_is_nearer = larger_is_nearer;
    return p;
}

// The colormaps as degree-6 polynomial fits of matplotlib's viridis and magma (Matt Zucker's
// CC0 fits, within about 1/255 of the tables): 14 numbers per map instead of two 256-entry
// tables, and the same colours on every machine.
using Poly = std::array<std::array<double, 3>, 7>;
constexpr Poly kViridis = {{{0.2777273272234177, 0.005407344544966578, 0.3340998053353061},
                            {0.1050930431085774, 1.404613529898575, 1.384590162594685},
                            {-0.3308618287255563, 0.214847559468213, 0.09509516302823659},
                            {-4.634230498983486, -5.799100973351585, -19.33244095627987},
                            {6.228269936347081, 14.17993336680509, 56.69055260068105},
                            {4.776384997670288, -13.74514537774601, -65.35303263337234},
                            {-5.435455855934631, 4.645852612178535, 26.3124352495832}}};
constexpr Poly kMagma = {{{-0.002136485053939582, -0.000749655052795221, -0.005386127855323933},
                          {0.2516605407371642, 0.6775232436837668, 2.494026599312351},
                          {8.353717279216625, -3.577719514958484, 0.3144679030132573},
                          {-27.66873308576866, 14.26473078096533, -13.64921318813922},
                          {52.17613981234068, -27.94360607168351, 12.94416944238394},
                          {-50.76852536473588, 29.04658282127291, 4.23415299384598},
                          {18.65570506591883, -11.48977351997711, -5.601961508734096}}};

std::array<std::uint8_t, 3> colormap_rgb(DumpColormap map, double t) {
    const Poly& c = map == DumpColormap::viridis ? kViridis : kMagma;
    t = std::clamp(t, 0.0, 1.0);
    std::array<std::uint8_t, 3> rgb{};
    for (std::size_t ch = 0; ch < 3; ++ch) {
        double v = c[6][ch];
        for (std::size_t i = 6; i-- > 0;) v = v * t + c[i][ch];  // Horner
        rgb[ch] = std::uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
    }
    return rgb;
}

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.5g", v);
    return text;
}

}  // namespace

std::vector<DumpPart> dump_parts(const OcclusionBuffer& buffer, const OcclusionMaps& maps) {
    if (maps.levels() < 1 || maps.level_width(0) != buffer.config().width || maps.level_height(0) != buffer.config().height)
        throw Error("dumps: the occlusion maps were not made for this buffer");
    // Maps that left out their pyramids (PyramidBuild::lazy) or make only the depth pyramid
    // their test reads (OcclusionMapsConfig::depth_pyramids): every pyramid is built here from
    // the same buffer, for the dump alone.
    std::optional<OcclusionMaps> with_both;
    const OcclusionMaps* pyramids = &maps;
    if (!maps.pyramid_built() || !maps.farthest_depth(0) || !maps.nearest_depth(0)) {
        OcclusionMapsConfig config = maps.config();
        config.depth_pyramids = DepthPyramids::both;
        config.pyramid = PyramidBuild::always;
        pyramids = &with_both.emplace(buffer, config);
        with_both->build(buffer);
    }
    std::vector<DumpPart> parts;
    const int sw = buffer.sample_width(), sh = buffer.sample_height();
    {
        std::vector<std::uint8_t> covered;
        buffer.read_coverage(covered);
        DumpPart p = make_part("buffer.coverage", "per sample: 1 covered by an occluder, 0 not", sw, sh, DumpColormap::viridis, false);
        for (std::uint8_t c : covered) p.values.push_back(float(c));
        parts.push_back(std::move(p));
    }
    {
        DumpPart p = make_part("buffer.depth", "per sample: conservative occluder depth as clip w (larger is farther), +inf no occluder",
                               sw, sh, DumpColormap::magma, false);
        buffer.read_depth(p.values);
        parts.push_back(std::move(p));
    }
    for (int k = 0; k < maps.levels(); ++k) {
        const int w = maps.level_width(k), h = maps.level_height(k);
        const std::string level = ".L" + std::to_string(k);
        DumpPart opacity = make_part("opacity" + level,
                                     "opacity pyramid level " + std::to_string(k) + ": covered samples / samples per cell", w, h,
                                     DumpColormap::viridis, false);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) opacity.values.push_back(pyramids->opacity(k, x, y));
        parts.push_back(std::move(opacity));
        // The two depth pyramids: 1/w per cell, one level's cells contiguous.
        const std::size_t n = std::size_t(w) * std::size_t(h);
        const auto depth_part = [&](const char* stem, const char* what, const float* cells) {
            DumpPart part = make_part(stem + level,
                                      std::string(what) + " pyramid level " + std::to_string(k) +
                                          " as 1/w (larger is nearer), +inf no occluder",
                                      w, h, DumpColormap::magma, true);
            part.values.assign(cells, cells + n);
            parts.push_back(std::move(part));
        };
        depth_part("maxz", "max-Z (hzb), the farthest depth of the covered samples:", pyramids->farthest_depth(k));
        depth_part("nbz", "no-background Z-buffer, the nearest depth of the covered samples:", pyramids->nearest_depth(k));
    }
    // Only filled (add_occluder_box) when the maps answer with it: otherwise all +inf, noise.
    if (maps.config().depth == DepthTest::deb) {
        DumpPart deb = make_part("deb", "depth estimation buffer: farthest depth of the occluder boxes as 1/w (larger is nearer), +inf none",
                                 maps.config().deb_width, maps.config().deb_height, DumpColormap::magma, true);
        deb.values = maps.depth_estimation();
        parts.push_back(std::move(deb));
    }
    return parts;
}

void write_maps_exr(const OcclusionBuffer& buffer, const OcclusionMaps& maps, const std::string& path) {
    write_maps_exr(dump_parts(buffer, maps), path);
}

void write_maps_exr(const std::vector<DumpPart>& parts, const std::string& path) {
    if (parts.empty()) throw Error(path + ": no parts to write");
    // OpenEXR requires the parts of one file to share the display window: the largest part.
    int full_w = 0, full_h = 0;
    for (const DumpPart& p : parts) {
        if (p.width < 1 || p.height < 1 || p.values.size() != std::size_t(p.width) * std::size_t(p.height))
            throw Error(path + ": part " + p.name + " does not match its size");
        full_w = std::max(full_w, p.width);
        full_h = std::max(full_h, p.height);
    }
    std::vector<detail::ImagePart> images;
    for (const DumpPart& p : parts) {
        detail::ImagePart image;
        image.width = p.width;
        image.height = p.height;
        image.channels = 1;
        image.type = detail::PixelType::float32;
        image.pixels = p.values.data();
        image.full_width = full_w;
        image.full_height = full_h;
        image.channel_names = {"Y"};
        // The EXR part name ("name" in the header): OIIO's openexr writer takes it from here.
        image.attributes = {{"oiio:subimagename", p.name}, {"homcull:quantity", p.quantity}, {"compression", "zip"}};  // zip: lossless
        images.push_back(std::move(image));
    }
    // `oiiotool --info -v` prints the metadata of the first part only (`-a` prints all): the
    // first part also lists every part's name, so that one look shows them all.
    std::string names;
    for (const DumpPart& p : parts) names += (names.empty() ? "" : ", ") + p.name;
    images.front().attributes.emplace_back("homcull:parts", names);
    // Several parts need a format that holds several images: a PNG cannot hold a dump.
    const std::string why = detail::image_backend().write(path, images.data(), images.size(), "");
    if (!why.empty()) throw Error(path + ": " + why);
}

ColormapPng colormap_png_size(int width, int height) {
    ColormapPng r;
    r.scale = std::max(1, (kMinPngWidth + width - 1) / std::max(width, 1));
    r.width = width * r.scale;
    r.height = height * r.scale + kLegendHeight;
    return r;
}

ColormapPng write_colormap_png(const DumpPart& part, const std::string& path) {
    if (part.width < 1 || part.height < 1 || part.values.size() != std::size_t(part.width) * std::size_t(part.height))
        throw Error(path + ": part " + part.name + " does not match its size");
    ColormapPng r = colormap_png_size(part.width, part.height);
    r.path = path;
    const bool depth = part.colormap == DumpColormap::magma;
    // Depths span their finite values (+inf is "no occluder", drawn apart); coverage and
    // opacity the fixed [0, 1], so that levels and frames compare by colour.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (float v : part.values) {
        if (!std::isfinite(v)) {
            ++r.no_occluder;
            continue;
        }
        lo = std::min(lo, double(v));
        hi = std::max(hi, double(v));
    }
    r.finite = lo <= hi;
    if (!depth) {
        lo = 0.0;
        hi = 1.0;
    }
    r.range_min = r.finite ? lo : 0.0;
    r.range_max = r.finite ? hi : 0.0;
    // t in [0, 1] along the colormap; depths drawn near = bright whichever way they are stored.
    auto t_of = [&](double v) {
        if (!depth) return v;
        if (hi <= lo) return 1.0;
        const double t = (v - lo) / (hi - lo);
        return part.larger_is_nearer ? t : 1.0 - t;
    };

    std::vector<std::uint8_t> image_rgb(std::size_t(r.width) * std::size_t(r.height) * 3);
    std::uint8_t* const pixels = image_rgb.data();
    auto put = [&](int x, int y, const std::uint8_t* rgb) {
        std::uint8_t* p = pixels + (std::size_t(y) * std::size_t(r.width) + std::size_t(x)) * 3;
        p[0] = rgb[0];
        p[1] = rgb[1];
        p[2] = rgb[2];
    };
    for (int y = 0; y < part.height; ++y)
        for (int x = 0; x < part.width; ++x) {
            const float v = part.values[std::size_t(y) * std::size_t(part.width) + std::size_t(x)];
            const std::array<std::uint8_t, 3> c = std::isfinite(v) ? colormap_rgb(part.colormap, t_of(double(v)))
                                                                   : std::array<std::uint8_t, 3>{kNoOccluderRgb[0], kNoOccluderRgb[1],
                                                                                                 kNoOccluderRgb[2]};
            for (int sy = 0; sy < r.scale; ++sy)
                for (int sx = 0; sx < r.scale; ++sx) put(x * r.scale + sx, y * r.scale + sy, c.data());
        }

    // The legend strip: dark background, a colour bar from the range's low end (left) to its
    // high end (right), the values at its ends and what the colours mean.
    const int y0 = part.height * r.scale;
    const std::uint8_t background[3] = {24, 24, 24};
    for (int y = y0; y < r.height; ++y)
        for (int x = 0; x < r.width; ++x) put(x, y, background);
    const int bar_x0 = 8, bar_x1 = r.width - 8;
    for (int x = bar_x0; x < bar_x1; ++x) {
        const double t = double(x - bar_x0) / double(std::max(1, bar_x1 - bar_x0 - 1));
        const std::array<std::uint8_t, 3> c = colormap_rgb(part.colormap, t);
        for (int y = y0 + 4; y < y0 + 16; ++y) put(x, y, c.data());
    }
    std::string left, right, second_left, second_right;
    if (!depth) {
        left = "0";
        right = "1";
        second_left = part.name + (r.finite ? " (values " + number(lo) + " .. " + number(hi) + ")" : "");
    } else {
        const char* unit = part.larger_is_nearer ? "1/w" : "w";
        // Far at the left, near at the right, whichever end of the stored range that is.
        const double far = part.larger_is_nearer ? lo : hi, near = part.larger_is_nearer ? hi : lo;
        left = r.finite ? "far " + std::string(unit) + " = " + number(far) : "no finite depth";
        right = r.finite ? "near " + std::string(unit) + " = " + number(near) : "";
        second_left = part.name;
        second_right = "green: no occluder (" + std::to_string(r.no_occluder) + " px)";
    }
    const detail::ImageBackend& images = detail::image_backend();
    const detail::LegendFont& font = detail::legend_font();
    r.text_drawn = font.found;
    if (font.found) {
        const detail::RgbCanvas canvas{r.width, r.height, pixels};
        const float white[3] = {0.92f, 0.92f, 0.92f}, green[3] = {0.0f, 200.0f / 255.0f, 90.0f / 255.0f};
        std::string why;
        bool ok = images.render_text(canvas, bar_x0, y0 + 31, left, 13, font.name, white, false, &why);
        if (!right.empty()) ok = ok && images.render_text(canvas, bar_x1, y0 + 31, right, 13, font.name, white, true, &why);
        ok = ok && images.render_text(canvas, bar_x0, y0 + 45, second_left, 12, font.name, white, false, &why);
        if (!second_right.empty()) ok = ok && images.render_text(canvas, bar_x1, y0 + 45, second_right, 12, font.name, green, true, &why);
        if (!ok) {
            r.text_drawn = false;
            r.note = "legend text failed: " + why;
        }
    } else {
        r.note = font.reason;
    }
    detail::write_rgb_pixels(path, r.width, r.height, pixels, "png");
    return r;
}

std::vector<ColormapPng> write_colormap_pngs(const std::vector<DumpPart>& parts, const std::string& dir) {
    std::vector<ColormapPng> written;
    nlohmann::json index = nlohmann::json::array();
    for (const DumpPart& part : parts) {
        const std::string file = part.name + ".png";
        written.push_back(write_colormap_png(part, dir + "/" + file));
        const ColormapPng& r = written.back();
        nlohmann::json entry = {{"part", part.name},
                                {"file", file},
                                {"quantity", part.quantity},
                                {"colormap", part.colormap == DumpColormap::viridis ? "viridis" : "magma"},
                                {"size", {r.width, r.height}},
                                {"scale", r.scale},
                                {"text_drawn", r.text_drawn}};
        // JSON has no infinity: a part without finite values has no range.
        entry["range"] = r.finite ? nlohmann::json{r.range_min, r.range_max} : nlohmann::json(nullptr);
        if (part.colormap == DumpColormap::magma) {
            entry["no_occluder_pixels"] = r.no_occluder;
            entry["no_occluder_rgb"] = {kNoOccluderRgb[0], kNoOccluderRgb[1], kNoOccluderRgb[2]};
            entry["near_is_bright"] = true;
        }
        if (!r.note.empty()) entry["note"] = r.note;
        index.push_back(std::move(entry));
    }
    const std::string path = dir + "/colormaps.json";
    write_file(path, index.dump(1) + "\n", "the colormap index");
    return written;
}

}  // namespace homcull
