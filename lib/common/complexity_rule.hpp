#pragma once
// The rule of Zhang's complexity filter (Zhang 1998, ch. 7; homcull/occluder_selection.hpp,
// filter_by_complexity), shared by the scene culler's candidates and the C interface's
// homcull_filter_by_complexity: a candidate is kept when its triangles per unit of its own
// surface are at most `factor` times the median over the candidates.
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace homcull::detail {

// A triangle's area, the term of a candidate's surface.
inline double triangle_area(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) { return 0.5 * glm::length(glm::cross(b - a, c - a)); }

// Triangles per unit of surface (the inverse of the mean triangle area). No area (degenerate
// triangles only) or a non-finite one: it hides nothing, infinitely dense.
inline double triangle_density(std::size_t triangles, double area) {
    if (!(area > 0.0) || !std::isfinite(area)) return std::numeric_limits<double>::infinity();
    return double(triangles) / area;
}

// The densest a kept candidate may be: `factor` times the median of densities[0, count), count
// > 0, which this reorders. Infinite densities count in the median: when they are most of the
// candidates, every candidate with a surface is kept.
inline double complexity_limit(double* densities, std::size_t count, double factor) {
    std::nth_element(densities, densities + count / 2, densities + count);
    return factor * densities[count / 2];
}

inline bool within_complexity(double density, double limit) { return density <= limit && std::isfinite(density); }

}  // namespace homcull::detail
