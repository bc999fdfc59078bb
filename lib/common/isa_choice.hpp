#pragma once
// An instruction set chosen for one caller instead of the whole process: the C interface's
// contexts each have their own (homcull.h). While an IsaScope is alive on a thread, every kernel
// looked up there (resolved_kernel.hpp, scalar_reference_selected) follows its choice, and tasks
// run through the caller's job system carry it (common/run_tasks.hpp). Without one, the
// process-wide select_isa applies.
#include <cstdint>
#include <string>

namespace homcull::detail {

struct IsaChoice {
    bool scalar = false;  // the plain reference paths
    int table_index = 0;  // the Highway dispatch-table entry of the SIMD target (when !scalar)
    const char* name = "";  // "avx2", "scalar", ... (a string literal: a choice holds no memory)
};

// The choice for a name as select_isa takes it ("best", "scalar", "avx2", ...). Throws
// homcull::Error for a name this CPU or build cannot run.
IsaChoice make_isa_choice(const std::string& name);

// Whether make_isa_choice accepts the name ("best" and "scalar" always). Allocates nothing.
bool isa_available(const char* name) noexcept;

// Whether the plain scalar reference paths are in force on this thread: its IsaChoice's, or
// select_isa's.
bool scalar_reference_selected();

// The choice in force on this thread (null: the process-wide one).
const IsaChoice* current_isa_choice() noexcept;

class IsaScope {
public:
    explicit IsaScope(const IsaChoice* choice) noexcept;
    ~IsaScope();
    IsaScope(const IsaScope&) = delete;
    IsaScope& operator=(const IsaScope&) = delete;

private:
    const IsaChoice* previous_;
};

}  // namespace homcull::detail
