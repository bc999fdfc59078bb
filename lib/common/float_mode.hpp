#pragma once
// The floating-point environment the library computes in: IEEE round to nearest, subnormal
// numbers kept (no flush-to-zero, no denormals-are-zero), exceptions masked. Its promise of the
// same bits on every instruction set and with any job system holds in that environment only.
// Engines often run with flush-to-zero and denormals-are-zero set for speed, and libraries may
// set them in the worker threads that run their tasks and leave them set: after Embree's ray
// queries, a oneTBB worker ran with both (MXCSR 0x9FC0), and a render whose bands ran on it gave
// other bits than on the calling thread (HiddenTriangleSkip.TrianglesWithoutADepthBoundStillCover,
// run after an Embree test in the same process). So every public entry point and every
// job-system task (run_tasks) computes under a StandardFloatMode, which sets the environment
// when the caller's differs and restores the caller's control bits on exit.
//
// x86: the MXCSR control bits (DAZ, exception masks, rounding, FTZ) are set to 0x1F80, the
// power-on default. AArch64 (GCC and Clang): FPCR's FIZ, AH, trap-enable, rounding and FZ bits
// are cleared. Elsewhere (MSVC on Arm64, for one) the environment is left as it is. Exception
// flags raised inside the library stay set for the caller.
//
// The guards cover OcclusionBuffer's renders, tests and read-backs, OcclusionMaps, the scene
// culler (construction and cull), gather_world_triangles, ObjectHierarchy::build,
// build_occluder_clusters and clip_from_world. A guard is a function's first statement, and the
// mode change is a compiler barrier for memory (the float work of these functions starts from
// loads), not a full fence for arithmetic on values already in registers, which C++ does not
// offer short of -frounding-math.
#include <atomic>
#include <cstdint>

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
#endif

namespace homcull::detail {

class StandardFloatMode {
public:
#if defined(__SSE2__) || defined(_M_X64)
    StandardFloatMode() noexcept : saved_(_mm_getcsr()) {
        if ((saved_ & kControl) != kStandard) _mm_setcsr((saved_ & ~kControl) | kStandard);
        std::atomic_signal_fence(std::memory_order_seq_cst);
    }
    ~StandardFloatMode() {
        std::atomic_signal_fence(std::memory_order_seq_cst);
        if ((saved_ & kControl) != kStandard) _mm_setcsr((_mm_getcsr() & ~kControl) | (saved_ & kControl));
    }

private:
    static constexpr unsigned kControl = 0xFFC0u;   // bits 6 (DAZ) to 15 (FTZ); below: the sticky flags
    static constexpr unsigned kStandard = 0x1F80u;  // every exception masked, round to nearest
    unsigned saved_;
#elif defined(__aarch64__)
    StandardFloatMode() noexcept : saved_(read()) {
        if ((saved_ & kControl) != 0) write(saved_ & ~kControl);
    }
    ~StandardFloatMode() {
        if ((saved_ & kControl) != 0) write((read() & ~kControl) | (saved_ & kControl));
    }

private:
    // FZ (24), RMode (22-23), the trap enables IOE..IXE (8-12) and IDE (15), and FEAT_AFP's
    // FIZ (0: subnormal inputs as zero) and AH (1).
    static constexpr std::uint64_t kControl = (1u << 24) | (3u << 22) | (0x1Fu << 8) | (1u << 15) | 3u;
    static std::uint64_t read() {
        std::uint64_t v;
        __asm__ volatile("mrs %0, fpcr" : "=r"(v) : : "memory");
        return v;
    }
    static void write(std::uint64_t v) { __asm__ volatile("msr fpcr, %0" : : "r"(v) : "memory"); }
    std::uint64_t saved_;
#else
    StandardFloatMode() noexcept {}
#endif
public:
    StandardFloatMode(const StandardFloatMode&) = delete;
    StandardFloatMode& operator=(const StandardFloatMode&) = delete;
};

}  // namespace homcull::detail
