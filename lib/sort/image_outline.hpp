#pragma once
// An object's outline in the image: its bounding box's eight corners, centrally projected from
// the eye onto the plane one unit along the view axis (the plane of the image extents,
// visibility_sorter.cpp). For a box wholly in front of the eye their convex hull holds the
// projection of everything in the box, so two objects whose corners a line parts cannot
// overlap on screen, and neither can hide the other. The lines tried are those along each
// object's longest axis on screen: for long thin objects lying across the view, much tighter
// than the outlines' bounding rectangles (the extent tree's).
#include <glm/glm.hpp>

namespace homcull::sort_detail {

struct ImageOutline {
    glm::vec2 corners[8];
    glm::vec2 across{0.0f};  // normal to the object's longest axis on screen (zero: none)
    float pad = 0;           // how far the true outline may lie outside the corners (roundings)
};

// Whether a line across either outline's longest axis parts the two with more than their pads
// between them (the separating axis theorem's test on two of its axes).
bool outlines_apart(const ImageOutline& a, const ImageOutline& b);

}  // namespace homcull::sort_detail
