#include <homcull/error.hpp>
#include <homcull/visibility_grid.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace homcull {

const char* grid_layout_name(GridLayout layout) { return layout == GridLayout::volume ? "volume" : "floors"; }

const GridPoint* VisibilityGrid::nearest(const glm::dvec3& eye) const {
    if (points.empty() || column_count() == 0 || !std::isfinite(eye.x) || !std::isfinite(eye.y) || !std::isfinite(eye.z)) return nullptr;
    const VisibilityGridHeader& h = header;
    // The eye's column, clamped into the lattice (an eye outside it searches from the edge).
    auto column_of = [&](double coordinate, double origin, std::uint32_t count) {
        const double c = std::floor((coordinate - origin) / h.spacing);
        return long(std::clamp(c, 0.0, double(count) - 1.0));
    };
    const long cx = column_of(eye.x, h.origin_x, h.columns_x);
    const long cz = column_of(eye.z, h.origin_z, h.columns_z);
    const glm::vec3 e(eye);
    const GridPoint* best = nullptr;
    double best_d2 = std::numeric_limits<double>::infinity();
    const long rings = long(std::max(h.columns_x, h.columns_z));
    for (long r = 0; r <= rings; ++r) {
        // Every point of ring r is at least (r - 1) spacings away horizontally from the eye's
        // column, or more when the eye lies outside the lattice.
        if (best && r >= 1) {
            const double gap = double(r - 1) * h.spacing;
            if (gap * gap > best_d2) break;
        }
        for (long z = cz - r; z <= cz + r; ++z) {
            if (z < 0 || z >= long(h.columns_z)) continue;
            const bool edge_row = z == cz - r || z == cz + r;
            for (long x = cx - r; x <= cx + r; x += edge_row ? 1 : 2 * std::max(r, 1L)) {
                if (x < 0 || x >= long(h.columns_x)) continue;
                const std::size_t c = std::size_t(x) + std::size_t(h.columns_x) * std::size_t(z);
                for (std::uint32_t p = column_first[c]; p < column_first[c + 1]; ++p) {
                    const glm::dvec3 d = glm::dvec3(points[p].position) - glm::dvec3(e);
                    const double d2 = glm::dot(d, d);
                    if (d2 < best_d2) {
                        best_d2 = d2;
                        best = &points[p];
                    }
                }
            }
        }
    }
    return best;
}

std::uint32_t VisibilityGrid::score(const GridPoint& point, std::uint32_t object) const {
    const std::size_t p = std::size_t(&point - points.data());
    const auto first = by_id_.begin() + by_id_first_[p], last = by_id_.begin() + by_id_first_[p + 1];
    const auto it = std::lower_bound(first, last, std::pair<std::uint32_t, std::uint32_t>(object, 0));
    return it != last && it->first == object ? it->second : 0;
}

void VisibilityGrid::index(std::size_t object_count, const std::string& source) {
    const VisibilityGridHeader& h = header;
    if (!(h.spacing > 0.0) || !std::isfinite(h.spacing)) throw Error(source + ": the grid spacing must be positive");
    if (column_first.size() != column_count() + 1 || column_first.front() != 0 || column_first.back() != points.size())
        throw Error(source + ": the grid's columns do not match its points");
    if (!std::is_sorted(column_first.begin(), column_first.end())) throw Error(source + ": the grid's columns are out of order");
    by_id_first_.assign(1, 0);
    by_id_.clear();
    std::size_t column = 0;
    for (std::size_t p = 0; p < points.size(); ++p) {
        const GridPoint& point = points[p];
        // nearest() finds a point only in its own column's x-z square (a little slack for rounding).
        while (column_first[column + 1] <= p) ++column;
        const double x0 = h.origin_x + double(column % h.columns_x) * h.spacing;
        const double z0 = h.origin_z + double(column / h.columns_x) * h.spacing;
        const double slack = 1e-3 * h.spacing;
        const double px = double(point.position.x), pz = double(point.position.z);
        if (!(px >= x0 - slack && px <= x0 + h.spacing + slack && pz >= z0 - slack && pz <= z0 + h.spacing + slack))
            throw Error(source + ": point " + std::to_string(p) + " lies outside its column " + std::to_string(column));
        for (const auto& [id, score] : point.occluders)
            if (id >= object_count)
                throw Error(source + ": point " + std::to_string(p) + " names object " + std::to_string(id) + ", but the scene has " +
                            std::to_string(object_count) + " objects");
        const std::size_t first = by_id_.size();
        by_id_.insert(by_id_.end(), point.occluders.begin(), point.occluders.end());
        std::sort(by_id_.begin() + long(first), by_id_.end());
        for (std::size_t k = first + 1; k < by_id_.size(); ++k)
            if (by_id_[k].first == by_id_[k - 1].first)
                throw Error(source + ": point " + std::to_string(p) + " lists object " + std::to_string(by_id_[k].first) + " twice");
        by_id_first_.push_back(std::uint32_t(by_id_.size()));
    }
}

}  // namespace homcull
