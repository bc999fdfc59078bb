// The dispatch module (isa_choice.hpp): the targets homcull knows by name, one IsaChoice per
// target this CPU and build can run, and the process-wide default that select_isa sets.
#include "common/isa_choice.hpp"

#include <homcull/error.hpp>
#include <homcull/isa.hpp>

#include <hwy/highway.h>
#include <hwy/targets.h>

#include <atomic>
#include <cstring>
#include <string>
#include <vector>

namespace homcull {
namespace detail {

namespace {

struct NamedTarget {
    const char* name;
    std::int64_t bits;
};
// Best first, as Highway prefers them; entry k is IsaChoice id k + 1 (id 0 is scalar).
// sve2_128 and sve_256 are Highway's builds for SVE vectors of exactly 128 (with SVE2) and 256
// bits: the CPU supports them only at that length.
const NamedTarget kTargets[] = {{"avx512", HWY_AVX3},      {"avx2", HWY_AVX2},       {"sse4", HWY_SSE4}, {"sve2_128", HWY_SVE2_128},
                                {"sve_256", HWY_SVE_256},  {"sve2", HWY_SVE2},       {"sve", HWY_SVE},   {"neon", HWY_NEON},
                                {"emu128", HWY_EMU128}};
static_assert(1 + sizeof kTargets / sizeof kTargets[0] == kIsaChoiceCount, "one choice per target, and scalar");

// The choices this CPU and build can run, made once: the dispatch-table entry of each comes
// from a hwy::ChosenTarget of our own, updated to that one target (the process-wide one, which
// HWY_DYNAMIC_DISPATCH reads, is left alone).
struct Choices {
    IsaChoice choice[kIsaChoiceCount];
    bool available[kIsaChoiceCount] = {};
    int best = 0;  // the id "best" gives

    Choices() {
        const std::int64_t cpu = hwy::SupportedTargets();
        hwy::ChosenTarget all;
        all.Update(cpu);
        choice[0] = {0, true, int(all.GetIndex()), "scalar"};
        available[0] = true;
        for (int k = 0; k < kIsaChoiceCount - 1; ++k) {
            const int id = k + 1;
            if (!(HWY_TARGETS & kTargets[k].bits) || !(cpu & kTargets[k].bits)) continue;
            hwy::ChosenTarget one;
            one.Update(kTargets[k].bits);
            choice[id] = {id, false, int(one.GetIndex()), kTargets[k].name};
            available[id] = true;
            if (best == 0) best = id;
        }
    }
};

const Choices& choices() {
    static const Choices c;
    return c;
}

std::atomic<const IsaChoice*> process_default{nullptr};

}  // namespace

const IsaChoice* isa_choice_by_id(int id) noexcept {
    const Choices& c = choices();
    return id >= 0 && id < kIsaChoiceCount && c.available[id] ? &c.choice[id] : nullptr;
}

const IsaChoice* find_isa_choice(const char* name) noexcept {
    const Choices& c = choices();
    if (std::strcmp(name, "best") == 0) return &c.choice[c.best];
    for (int id = 0; id < kIsaChoiceCount; ++id)
        if (c.available[id] && std::strcmp(name, c.choice[id].name) == 0) return &c.choice[id];
    return nullptr;
}

const IsaChoice& isa_choice(const std::string& name) {
    if (const IsaChoice* c = find_isa_choice(name.c_str())) return *c;
    std::string known;
    for (const std::string& n : available_isas()) known += (known.empty() ? "" : ", ") + n;
    for (const NamedTarget& t : kTargets)
        if (name == t.name) throw Error("instruction set '" + name + "' is not available on this machine or in this build (available: best, " + known + ")");
    throw Error("unknown instruction set '" + name + "' (available: best, " + known + ")");
}

const IsaChoice& default_isa_choice() noexcept {
    const IsaChoice* c = process_default.load(std::memory_order_acquire);
    return c ? *c : *find_isa_choice("best");
}

}  // namespace detail

std::vector<std::string> available_isas() {
    std::vector<std::string> names;
    for (int id = 0; id < detail::kIsaChoiceCount; ++id)
        if (const detail::IsaChoice* c = detail::isa_choice_by_id(id)) names.push_back(c->name);
    return names;
}

// Checks the name first: a name that cannot be selected throws and leaves the selection as it was.
void select_isa(const std::string& name) { detail::process_default.store(&detail::isa_choice(name), std::memory_order_release); }

std::string selected_isa() { return detail::default_isa_choice().name; }

}  // namespace homcull
