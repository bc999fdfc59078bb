// homcull bench --workload frame --scaling (bench_scaling.hpp).
#include "bench_scaling.hpp"

#include "options.hpp"
#include "stage_times.hpp"

#include <homcull/error.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <memory>
#include <string>
#include <thread>

#ifdef __linux__
#include <sched.h>
#endif

namespace homcull::cli {
namespace {

// Every copy of the ceiling waits here until all have come (they start their frames together),
// or until the line is abandoned (a copy could not start).
class StartLine {
public:
    explicit StartLine(int count) : count_(count) {}
    // Whether every copy came (false: abandoned).
    bool arrive_and_wait() {
        arrived_.fetch_add(1);
        while (arrived_.load() < count_)
            if (abandoned_.load()) return false;
            else std::this_thread::yield();
        return true;
    }
    void abandon() { abandoned_.store(true); }

private:
    const int count_;
    std::atomic<int> arrived_{0};
    std::atomic<bool> abandoned_{false};
};

// The view culled twice in a row by `culler`; the second cull's time, without the first as its
// history (a temporal strategy would draw only what the first found visible).
double second_cull_ms(SceneCuller& culler, const Camera& camera, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel) {
    culler.cull(camera, answers, parallel);
    culler.reset_history();
    const long long start = now_ns();
    culler.cull(camera, answers, parallel);
    return elapsed_ms(start);
}

// The ceiling's frame: every copy culls the view twice in a row on its own thread (the calling
// thread is copy 0), the copies' second culls started together; the slowest copy's time. A copy
// that throws, or a thread that cannot start, ends the measurement with that error.
double copies_at_once_ms(std::vector<std::unique_ptr<SceneCuller>>& copies, const Camera& camera) {
    const int n = int(copies.size());
    StartLine warm(n), timed(n);
    std::vector<double> ms(copies.size(), 0.0);
    std::vector<std::exception_ptr> errors(copies.size());
    const auto run_copy = [&](int k) {
        try {
            std::vector<OccludeeAnswer> answers;
            if (!warm.arrive_and_wait()) return;
            copies[std::size_t(k)]->cull(camera, answers);
            copies[std::size_t(k)]->reset_history();  // as second_cull_ms
            if (!timed.arrive_and_wait()) return;
            const long long start = now_ns();
            copies[std::size_t(k)]->cull(camera, answers);
            ms[std::size_t(k)] = elapsed_ms(start);
        } catch (...) {
            errors[std::size_t(k)] = std::current_exception();
            warm.abandon(), timed.abandon();
        }
    };
    std::vector<std::thread> helpers;
    try {
        for (int k = 1; k < n; ++k) helpers.emplace_back(run_copy, k);
    } catch (...) {
        warm.abandon(), timed.abandon();
        for (std::thread& t : helpers) t.join();
        throw;
    }
    run_copy(0);
    for (std::thread& t : helpers) t.join();
    for (const std::exception_ptr& e : errors)
        if (e) std::rethrow_exception(e);
    return *std::max_element(ms.begin(), ms.end());
}

void wait_for(const std::atomic<int>& turn, int value) {
    // Spinning, but giving way now and then: should both threads share a core, each trip then
    // costs a switch instead of a time slice.
    for (unsigned spins = 1; turn.load(std::memory_order_acquire) != value; ++spins)
        if (spins % 1024 == 0) std::this_thread::yield();
}

// How long a cache line takes to go from one core to another and back: two threads hand a
// counter to each other `trips` times. What a second thread gains on work that shares data (a
// cluster set up on one core and drawn on the other, buffer rows written on one and tested on
// the other) falls as this rises, and a virtual machine's two cores can be close (one chiplet)
// or far apart from one minute to the next; the ceiling's copies share nothing and do not show it.
double cross_core_round_trip_ns(int trips) {
    // The job system's workers spin a while after their last task before they sleep: sharing a
    // core with one, a thread here would time the scheduler instead.
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    alignas(64) std::atomic<int> turn{0};
    StartLine start(2);
    std::thread other([&] {
        if (!start.arrive_and_wait()) return;
        for (int k = 0; k < trips; ++k) {
            wait_for(turn, 2 * k + 1);
            turn.store(2 * k + 2, std::memory_order_release);
        }
    });
    start.arrive_and_wait();
    const long long begin = now_ns();
    for (int k = 0; k < trips; ++k) {
        turn.store(2 * k + 1, std::memory_order_release);
        wait_for(turn, 2 * k + 2);
    }
    const double ns = double(now_ns() - begin) / double(trips);
    other.join();
    return ns;
}

nlohmann::json spread(std::vector<double> v) {
    return {{"median", median(v)}, {"min", *std::min_element(v.begin(), v.end())}, {"max", *std::max_element(v.begin(), v.end())}};
}

}  // namespace

void check_scaling_threads(int threads) {
    if (threads < 2) throw Error("bench --scaling: give --threads N with N >= 2, got " + std::to_string(threads));
    int cores = int(std::thread::hardware_concurrency());
#ifdef __linux__
    cpu_set_t allowed;  // a process limited by taskset has fewer
    if (sched_getaffinity(0, sizeof allowed, &allowed) == 0) cores = CPU_COUNT(&allowed);
#endif
    if (cores != 0 && threads > cores)
        throw Error("bench --scaling: --threads " + std::to_string(threads) + " exceeds the " + std::to_string(cores) +
                    " hardware threads this process may use (the ceiling's copies would share cores)");
}

nlohmann::json measure_thread_scaling(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config,
                                      const CameraPath& views, int rounds, int threads, const ParallelFor& parallel) {
    check_scaling_threads(threads);
    if (!parallel.run) throw Error("bench --scaling: no job system to run the threads");
    // The one-thread culler and the copies run on one thread each, as cull --threads 1 does.
    SceneCullerConfig serial = config, threaded = config;
    serial.job_system = false, threaded.job_system = true;
    SceneCuller one(scene, occluders, serial), many(scene, occluders, threaded);
    std::vector<std::unique_ptr<SceneCuller>> copies;
    for (int k = 0; k < threads; ++k) copies.push_back(std::make_unique<SceneCuller>(scene, occluders, serial));

    const std::size_t count = views.frames.size();
    std::vector<std::vector<double>> t_one(count), t_many(count), t_copies(count);
    std::vector<StageTimes> stages_one(count), stages_many(count);
    std::vector<double> speedup, ceiling, round_trip;  // per round: over the sums of its views' times
    std::vector<OccludeeAnswer> answers;
    for (int r = 0; r < rounds; ++r) {
        round_trip.push_back(cross_core_round_trip_ns(20000));
        double one_sum = 0.0, many_sum = 0.0, copies_sum = 0.0;
        for (std::size_t v = 0; v < count; ++v) {
            const Camera& camera = views.frames[v];
            t_one[v].push_back(second_cull_ms(one, camera, answers, ParallelFor{}));
            stages_one[v].add(one.timings());
            t_many[v].push_back(second_cull_ms(many, camera, answers, parallel));
            stages_many[v].add(many.timings());
            t_copies[v].push_back(copies_at_once_ms(copies, camera));
            one_sum += t_one[v].back(), many_sum += t_many[v].back(), copies_sum += t_copies[v].back();
        }
        speedup.push_back(one_sum / many_sum);
        ceiling.push_back(double(threads) * one_sum / copies_sum);
    }
    // The headline ratios from the views' medians (a round's sum takes every stall of its views).
    double one_mean = 0.0, many_mean = 0.0, copies_mean = 0.0;
    for (std::size_t v = 0; v < count; ++v) {
        one_mean += median(t_one[v]) / double(count);
        many_mean += median(t_many[v]) / double(count);
        copies_mean += median(t_copies[v]) / double(count);
    }
    return {{"threads", threads},
            {"rounds", rounds},
            {"frame_ms_mean", {{"one_thread", one_mean}, {"threads", many_mean}, {"copies_at_once", copies_mean}}},
            {"stages_ms_mean", {{"one_thread", stage_means(stages_one)}, {"threads", stage_means(stages_many)}}},
            {"speedup", one_mean / many_mean},
            {"ceiling", double(threads) * one_mean / copies_mean},
            {"per_round", {{"speedup", spread(speedup)}, {"ceiling", spread(ceiling)}}},
            // Each round's figures in order, so that a round's speed-up can be read beside the
            // round trip measured just before it (the host moves the cores within a run).
            {"rounds_in_order", {{"speedup", speedup}, {"ceiling", ceiling}, {"cross_core_round_trip_ns", round_trip}}},
            {"cross_core_round_trip_ns", spread(round_trip)}};
}

}  // namespace homcull::cli
