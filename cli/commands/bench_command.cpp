// `gale bench`: evaluate an expression over N random points in [-50,50]^3 (fixed seed, the
// same points on every machine), repeat, and print the best time per point.
#include "cli/commands.h"
#include "cli/common.h"
#include "geometry/file_policy.h"

#include <CLI/CLI.hpp>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <memory>
#include <random>

namespace gale::cli {

namespace {

// Positions (24 bytes a point) and results (up to 16 doubles) are held in memory.
constexpr long long kMaxBenchPoints = 100'000'000;

// 3N coordinates, uniform in [-50,50): mt19937_64 is specified bit for bit, and the mapping to
// [0,1) is ours (std::uniform_real_distribution differs between standard libraries).
std::vector<double> randomPoints(size_t n) {
    std::mt19937_64 rng(0x6a1e5eedULL);
    std::vector<double> p(3 * n);
    for (double& v : p) v = -50.0 + 100.0 * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
    return p;
}

template <class T>
int benchLoop(const runtime::Program& program, const runtime::EvalRequest& request, int repeat,
              double& bestSeconds, int& runs, std::string& error) {
    const int width = program.resultIsString() ? 1 : program.resultWidth();
    std::vector<T> buffer(request.count * static_cast<size_t>(width));
    std::vector<std::string> strings(program.resultIsString() ? request.count : 0);
    runtime::EvalOutput<T> out;
    out.data = buffer.data();
    out.pointStride = width;
    out.strings = strings.empty() ? nullptr : strings.data();
    using Clock = std::chrono::steady_clock;
    // One untimed warm-up run (page faults, thread pool start-up).
    runtime::EvalResult r = runtime::evaluate<T>(program, request, out);
    if (!r.ok) {
        error = r.error;
        return kExitInput;
    }
    double total = 0.0;
    bestSeconds = 1e300;
    runs = 0;
    while (true) {
        Clock::time_point a = Clock::now();
        runtime::evaluate<T>(program, request, out);
        double s = std::chrono::duration<double>(Clock::now() - a).count();
        bestSeconds = std::min(bestSeconds, s);
        total += s;
        ++runs;
        if (repeat > 0 ? runs >= repeat : (total >= 0.5 && runs >= 3) || runs >= 10000) break;
    }
    return kExitOk;
}

} // namespace

int runBench(const BenchOptions& o) {
    if (o.points < 1 || o.points > kMaxBenchPoints) {
        printError("--points must be from 1 to " + std::to_string(kMaxBenchPoints) +
                   " (the points and results are held in memory: 10^8 take several GB)");
        return kExitUsage;
    }
    if (o.repeat < 0 || o.threads < 0) {
        printError("--repeat and --threads must not be negative");
        return kExitUsage;
    }
    std::vector<SetValue> sets;
    if (!parseSets(o.source.sets, sets)) return kExitUsage;
    lang::SourceFile source;
    if (int rc = loadSource(o.source.file, o.source.expr, source)) return rc;

    const size_t n = static_cast<size_t>(o.points);
    std::vector<double> positions = randomPoints(n);
    Bindings bindings(o.time, o.time * 24.0, 24.0);
    bindings.setVarying("P", 3, positions.data(), 3, 1);
    bindings.addSets(sets);
    const geometry::FileAccess files = geometry::fileAccessFor(o.source.file, o.source.allowPaths);
    std::shared_ptr<const runtime::Program> program = compileAndReport(
        source, bindings.variables(), wantWidthFor(o.source.type), nullptr, &files);
    if (!program) return kExitInput;

    runtime::EvalRequest request;
    request.count = n;
    bindings.fillRequest(request);
    request.threads = o.threads;
    double best = 0.0;
    int runs = 0;
    std::string error;
    const bool asFloat = o.precision != "double";
    int rc = asFloat ? benchLoop<float>(*program, request, o.repeat, best, runs, error)
                     : benchLoop<double>(*program, request, o.repeat, best, runs, error);
    if (rc) {
        printError("cannot evaluate " + source.name() + ": " + error);
        return rc;
    }
    const double nsPerPoint = best * 1e9 / static_cast<double>(n);
    const int threads = o.threads > 0 ? o.threads : tbb::info::default_concurrency();
    char ns[64];
    if (o.json) {
        std::snprintf(ns, sizeof ns, "%.4g", nsPerPoint);
        std::cout << "{\"ns_per_point\": " << ns << ", \"points\": " << n
                  << ", \"threads\": " << threads << ", \"precision\": \""
                  << (asFloat ? "float" : "double") << "\", \"runs\": " << runs << "}\n";
    } else {
        std::snprintf(ns, sizeof ns, "%.3g", nsPerPoint);
        std::cout << "ns/point: " << ns << "  (points " << n << ", threads " << threads
                  << ", precision " << (asFloat ? "float" : "double") << ", best of " << runs
                  << ")\n";
    }
    std::cout.flush();
    return std::cout ? kExitOk : kExitIo;
}

Command addBenchCommand(CLI::App& app) {
    auto o = std::make_shared<BenchOptions>();
    CLI::App* sub = app.add_subcommand(
        "bench", "Evaluate an expression over N random points uniformly in [-50,50]^3 (fixed "
                 "seed), repeat, and print the best nanoseconds per point.");
    addSourceOptions(*sub, o->source);
    sub->add_option("--points", o->points, "Number of random points")->capture_default_str();
    sub->add_option("--threads", o->threads, "Threads; 0 = all hardware threads")
        ->capture_default_str()
        ->check(CLI::Range(0, 4096));
    sub->add_option("--precision", o->precision, "Evaluate in float or double")
        ->check(CLI::IsMember({"float", "double"}))
        ->capture_default_str();
    sub->add_option("--repeat", o->repeat,
                    "Timed runs (default: repeat until 0.5 s in total and at least 3 runs)")
        ->type_name("R");
    sub->add_option("--time", o->time, "$t in seconds ($frame = t*24, $fps = 24)")
        ->capture_default_str();
    sub->add_flag("--json", o->json,
                  "Print {\"ns_per_point\": ..., \"points\": ..., \"threads\": ..., \"precision\": "
                  "..., \"runs\": ...}");
    return {sub, [o] { return runBench(*o); }};
}

} // namespace gale::cli
