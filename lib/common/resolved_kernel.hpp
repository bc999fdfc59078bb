#pragma once
// The function that a Highway dispatch table (HWY_EXPORT) holds for the chosen target, looked
// up once so that hot loops call it directly. HWY_DYNAMIC_DISPATCH asks libhwy for the chosen
// target at every call (a call through the PLT and an atomic load), which the rasterizer paid
// once per triangle and the rectangle tests once per rectangle. Use it in the translation unit
// of the HWY_EXPORT (after HWY_ONCE): GetIndex must see that unit's compiled targets.
#include "common/isa_choice.hpp"

#include <hwy/highway.h>

namespace homcull::detail {

template <typename Function>
Function resolved_kernel(Function const* dispatch_table) {
    if (const IsaChoice* choice = current_isa_choice()) return dispatch_table[choice->table_index];  // a caller's own (isa_choice.hpp)
    hwy::ChosenTarget& chosen = hwy::GetChosenTarget();
    // What the table's first entry does on the first call (and after select_isa resets it).
    if (!chosen.IsInitialized()) chosen.Update(hwy::SupportedTargets());
    return dispatch_table[chosen.GetIndex()];
}

}  // namespace homcull::detail

// The chosen target's function of an HWY_EXPORT-ed function FUNC.
#define HOMCULL_RESOLVED_KERNEL(FUNC) ::homcull::detail::resolved_kernel(HWY_DISPATCH_TABLE(FUNC))
