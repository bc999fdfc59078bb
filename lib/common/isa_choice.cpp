// The instruction-set choice: the targets homcull knows by name, the process-wide selection
// (select_isa) and a caller's own (IsaChoice, isa_choice.hpp), which every layer's kernels
// follow when they look up their Highway dispatch table (resolved_kernel.hpp).
#include "common/isa_choice.hpp"

#include <homcull/error.hpp>
#include <homcull/isa.hpp>

#include <hwy/highway.h>
#include <hwy/targets.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <iterator>
#include <string>
#include <vector>

namespace homcull {
namespace detail {

namespace {

// The plain scalar reference paths, process-wide (select_isa("scalar")).
std::atomic<bool> use_reference{false};

struct NamedTarget {
    const char* name;
    std::int64_t bits;
};
// Best first, as Highway prefers them. sve2_128 and sve_256 are Highway's builds for SVE
// vectors of exactly 128 (with SVE2) and 256 bits: the CPU supports them only at that length.
const NamedTarget kTargets[] = {{"avx512", HWY_AVX3},      {"avx2", HWY_AVX2},       {"sse4", HWY_SSE4}, {"sve2_128", HWY_SVE2_128},
                                {"sve_256", HWY_SVE_256},  {"sve2", HWY_SVE2},       {"sve", HWY_SVE},   {"neon", HWY_NEON},
                                {"emu128", HWY_EMU128}};

thread_local const IsaChoice* current_choice = nullptr;

// The CPU's own targets, read once, before select_isa forces one: while a target is forced,
// Highway's SupportedTargets() returns only that one. (Lifting the force to read them again
// would change what renders and queries on other threads dispatch to.)
std::int64_t cpu_targets() {
    static const std::int64_t cpu = hwy::SupportedTargets();
    return cpu;
}

// The Highway target bits of a name ("best": 0), or throws. `scalar` tells the reference paths.
std::int64_t target_bits(const std::string& name, bool& scalar) {
    scalar = name == "scalar";
    if (scalar || name == "best") return 0;
    const auto t = std::find_if(std::begin(kTargets), std::end(kTargets), [&](const auto& k) { return name == k.name; });
    if (t == std::end(kTargets)) {
        std::string known;
        for (const std::string& n : available_isas()) known += (known.empty() ? "" : ", ") + n;
        throw Error("unknown instruction set '" + name + "' (available: best, " + known + ")");
    }
    if (!(HWY_TARGETS & t->bits) || !(cpu_targets() & t->bits))
        throw Error("instruction set '" + name + "' is not available on this machine or in this build");
    return t->bits;
}

}  // namespace

bool scalar_reference_selected() {
    const IsaChoice* choice = current_isa_choice();
    return choice ? choice->scalar : use_reference.load();
}

const IsaChoice* current_isa_choice() noexcept { return current_choice; }
IsaScope::IsaScope(const IsaChoice* choice) noexcept : previous_(current_choice) { current_choice = choice; }
IsaScope::~IsaScope() { current_choice = previous_; }

bool isa_available(const char* name) noexcept {
    if (std::strcmp(name, "best") == 0 || std::strcmp(name, "scalar") == 0) return true;
    for (const auto& t : kTargets)
        if (std::strcmp(name, t.name) == 0) return (HWY_TARGETS & t.bits) && (cpu_targets() & t.bits);
    return false;
}

// The dispatch-table entry comes from a ChosenTarget of our own, updated to the one target (or
// to every target the CPU has, for "best"): the process-wide one is left alone.
IsaChoice make_isa_choice(const std::string& name) {
    IsaChoice choice;
    const std::int64_t bits = target_bits(name, choice.scalar);
    const std::int64_t targets = bits ? bits : cpu_targets();
    hwy::ChosenTarget chosen;
    chosen.Update(targets);
    choice.table_index = int(chosen.GetIndex());
    choice.name = "scalar";
    if (!choice.scalar)
        for (const auto& t : kTargets)
            if (HWY_TARGETS & targets & t.bits) {
                choice.name = t.name;  // the best one the table will give
                break;
            }
    return choice;
}

}  // namespace detail

std::vector<std::string> available_isas() {
    std::vector<std::string> names = {"scalar"};
    const std::int64_t supported = detail::cpu_targets();
    for (const auto& t : detail::kTargets)
        if ((HWY_TARGETS & t.bits) && (supported & t.bits)) names.push_back(t.name);
    return names;
}

// Checks the name first: a name that cannot be selected throws and leaves the selection as it was.
void select_isa(const std::string& name) {
    bool scalar = false;
    const std::int64_t bits = detail::target_bits(name, scalar);
    detail::use_reference = scalar;
    if (scalar) return;  // the SIMD targets stay as they were: the scalar paths do not dispatch
    hwy::SetSupportedTargetsForTest(bits);
}

std::string selected_isa() {
    if (detail::use_reference) return "scalar";
    const std::int64_t target = hwy::SupportedTargets() & HWY_TARGETS;
    for (const auto& t : detail::kTargets)
        if (target & t.bits) return t.name;  // the best one Highway will dispatch to
    return "unknown";
}

}  // namespace homcull
