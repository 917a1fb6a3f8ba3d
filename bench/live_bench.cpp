// gale live's latency (issue 17): an edit of the ice cape's expression on disk -> the inotify
// event -> the scene reloaded and recompiled -> a new 128^2 slice, 16^3 arrows and 256 rake
// streamlines -> their JSON, each stage timed, over repeated edits. The baseline, measured in
// the same run, samples the same number of points in one batch (the field's raw cost).
#include "fields/grid_sample.h"
#include "io/atomic_file.h"
#include "live/field_frame.h"
#include "live/json.h"
#include "live/project.h"
#include "live/watcher.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <vector>

using namespace gale;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double ms(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

struct Stats {
    std::vector<double> v;
    void add(double x) { v.push_back(x); }
    double median() {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    }
    double max() { return *std::max_element(v.begin(), v.end()); }
};

} // namespace

int main(int argc, char** argv) {
    const int edits = argc > 1 ? std::atoi(argv[1]) : 20;
    char tmpl[] = "/tmp/gale_live_bench_XXXXXX";
    const fs::path dir = mkdtemp(tmpl);
    fs::copy(fs::path(GALE_SOURCE_DIR) / "examples/05_ice_cape", dir, fs::copy_options::recursive);
    const std::string scene = (dir / "scene.toml").string(), se = (dir / "ice_wind.se").string();
    std::string text;
    {
        std::ifstream in(se);
        std::stringstream s;
        s << in.rdbuf();
        text = s.str();
    }

    live::Project project(scene);
    if (!project.load()) {
        std::fprintf(stderr, "the ice cape does not load\n");
        return 1;
    }
    live::FieldRequest request;
    request.time = 1.0;
    request.axis = 0;
    request.res = 128;
    request.arrows = 16;
    const viz::Box3 box = project.box();
    request.rake.count = 256;
    request.rake.a = {box.lo[0] + 0.02 * (box.hi[0] - box.lo[0]), box.lo[1], box.lo[2]};
    request.rake.b = {request.rake.a[0], box.hi[1], box.hi[2]};

    std::mutex m;
    std::condition_variable cv;
    Clock::time_point seen;
    bool fired = false;
    live::FileWatcher watcher(
        [&](const std::set<std::string>&) {
            std::lock_guard<std::mutex> lock(m);
            seen = Clock::now();
            fired = true;
            cv.notify_all();
        },
        15);
    std::string error;
    if (!watcher.start(error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return 1;
    }
    watcher.watch({project.files().begin(), project.files().end()});

    Stats write, event, reload, slice, arrows, lines, json, total, baseline;
    size_t points = 0, bytes = 0;
    for (int i = 0; i < edits + 2; ++i) {
        // An edit: a new size of the eddies each time (0.5, 0.51, ... m), as a slider gives, so
        // the turbulence is synthesised anew (no cached tile fits).
        std::string edited = text;
        const std::string from = "$turbulenceScale = 0.5;";
        edited.replace(edited.find(from), from.size(),
                       "$turbulenceScale = " + std::to_string(0.5 + 0.01 * i) + ";");
        {
            std::lock_guard<std::mutex> lock(m);
            fired = false;
        }
        const Clock::time_point t0 = Clock::now();
        io::writeBytesAtomic(se, edited);
        const Clock::time_point t1 = Clock::now();
        {
            std::unique_lock<std::mutex> lock(m);
            if (!cv.wait_for(lock, std::chrono::seconds(5), [&] { return fired; })) {
                std::fprintf(stderr, "no inotify event within 5 s\n");
                return 1;
            }
        }
        const Clock::time_point t2 = seen;
        if (!project.load()) return 1;
        const Clock::time_point t3 = Clock::now();
        live::FieldFrame frame;
        if (!live::computeFieldFrame(*project.field(), project.fps(), project.box(), request, frame,
                                     error)) {
            std::fprintf(stderr, "%s\n", error.c_str());
            return 1;
        }
        const Clock::time_point t4 = Clock::now();
        const std::string doc = live::fieldJson(frame, project.overlays(request.time)).dump();
        const Clock::time_point t5 = Clock::now();
        bytes = doc.size();

        // Baseline: the same number of points as the frame sampled, in one batch.
        points = frame.slice.velocity.size() / 3 + frame.arrows.positions.size() / 3;
        for (const viz::Streamline& l : frame.streamlines)
            points += 2 * l.points.size(); // two RK2 stages
        std::vector<double> pos(3 * points), vel(3 * points);
        for (size_t k = 0; k < points; ++k)
            for (int c = 0; c < 3; ++c)
                pos[3 * k + c] = box.lo[c] + (box.hi[c] - box.lo[c]) *
                                                 ((k * (c + 7) * 2654435761u) % 1000) / 1000.0;
        fields::SampleTime when;
        when.time = request.time;
        when.fps = project.fps();
        when.threads = 0;
        const Clock::time_point b0 = Clock::now();
        fields::samplePoints(*project.field(), pos.data(), points, when, vel.data());
        const Clock::time_point b1 = Clock::now();
        if (i < 2) continue; // warm-up
        write.add(ms(t0, t1));
        event.add(ms(t1, t2));
        reload.add(ms(t2, t3));
        slice.add(frame.times.slice);
        arrows.add(frame.times.arrows);
        lines.add(frame.times.streamlines);
        json.add(ms(t4, t5));
        total.add(ms(t0, t5));
        baseline.add(ms(b0, b1));
    }
    watcher.stop();
    fs::remove_all(dir);
    std::printf("gale live latency, ice cape, %d edits (medians, max in brackets), ms:\n", edits);
    std::printf("  write .se (atomic)          %7.2f  (%.2f)\n", write.median(), write.max());
    std::printf("  inotify event (15 ms settle) %6.2f  (%.2f)\n", event.median(), event.max());
    std::printf("  reload + compile scene      %7.2f  (%.2f)\n", reload.median(), reload.max());
    std::printf("  slice 128^2                 %7.2f  (%.2f)\n", slice.median(), slice.max());
    std::printf("  arrows 16^3                 %7.2f  (%.2f)\n", arrows.median(), arrows.max());
    std::printf("  streamlines 256 x <=129     %7.2f  (%.2f)\n", lines.median(), lines.max());
    std::printf("  JSON (%zu kB)              %7.2f  (%.2f)\n", bytes / 1024, json.median(),
                json.max());
    const double t = total.median(), b = baseline.median();
    std::printf("  total edit -> data ready    %7.2f  (%.2f)   goal <= 100\n", t, total.max());
    std::printf("baseline: %zu points sampled in one batch %.2f ms; marks / baseline = %.2f\n",
                points, b, (slice.median() + arrows.median() + lines.median()) / b);
    return 0;
}
