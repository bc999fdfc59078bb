#pragma once
// The dispatch module: the instruction sets homcull knows by name, the choice of one, and the
// process-wide default that select_isa (homcull/isa.hpp) sets. A choice is chosen per buffer,
// as MOC's Create and Embree's devices do: each layer resolves its kernels for a choice once,
// into one table of function pointers (raster/raster_kernels.hpp, buffer/buffer_kernels.hpp,
// hom/map_kernels.hpp), and a buffer holds a pointer to its table. Nothing here changes
// Highway's process-wide target (hwy::SetSupportedTargetsForTest is a test hook): a choice
// indexes each kernel's Highway dispatch table (HWY_EXPORT) itself.
#include <cstdint>
#include <string>

namespace homcull::detail {

struct IsaChoice {
    int id = 0;           // 0 for scalar, then one per named target: indexes per-choice tables
    bool scalar = false;  // the plain reference paths
    // The Highway dispatch-table entry of the SIMD target. For the scalar choice, the best target
    // the CPU has: the few kernels without a scalar reference (integer work with one answer on
    // every target: the draw order's buckets, the dropping of hidden noted triangles) run there.
    int table_index = 0;
    const char* name = "";  // "avx2", "scalar", ... (a string literal)
};

// One more than the largest IsaChoice::id.
constexpr int kIsaChoiceCount = 10;

// The choice for a name as select_isa takes it ("best", "scalar", "avx2", ...): one object per
// instruction set, alive for the whole process; "best" gives the best target's. Null for a
// name this CPU or build cannot run. Allocates nothing.
const IsaChoice* find_isa_choice(const char* name) noexcept;
// The same, throwing homcull::Error that lists the available names.
const IsaChoice& isa_choice(const std::string& name);

// The process-wide default (select_isa's; "best" until it is called): what a buffer made
// without naming an instruction set runs.
const IsaChoice& default_isa_choice() noexcept;

// The choice with this id, or null when this CPU or build cannot run it.
const IsaChoice* isa_choice_by_id(int id) noexcept;

// The table of a layer's kernels for a choice: resolve(choice) for every choice this CPU runs,
// computed once, on first use, from any thread (a function-local static).
template <typename Table, Table (*resolve)(const IsaChoice&)>
const Table& kernel_table(const IsaChoice& choice) {
    struct Tables {
        Table table[kIsaChoiceCount] = {};
        Tables() {
            for (int id = 0; id < kIsaChoiceCount; ++id)
                if (const IsaChoice* c = isa_choice_by_id(id)) table[id] = resolve(*c);
        }
    };
    static const Tables tables;
    return tables.table[choice.id];
}

}  // namespace homcull::detail

// The function of an HWY_EXPORT-ed FUNC for a choice. Use it in the translation unit of the
// HWY_EXPORT, after HWY_ONCE.
#define HOMCULL_KERNEL_FOR(CHOICE, FUNC) (HWY_DISPATCH_TABLE(FUNC)[(CHOICE).table_index])
