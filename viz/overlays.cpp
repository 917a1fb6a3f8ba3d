// What a viz picture shows besides the wind: a scene's rigs at a time (windicator, gust bands,
// gust timeline) and simulated cloth and hair read from gale sim's frame files.
#include "viz/overlays.h"

#include "fields/rigs.h"
#include "io/pointset.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace gale::viz {

namespace fs = std::filesystem;

namespace {

// Samples of a gust's strength * envelope at the origin plane, from just before its start to
// just after it has died away.
TimelineOverlay::Curve gustCurve(const fields::Gust& g, const std::string& label) {
    TimelineOverlay::Curve c;
    c.label = label;
    const double total = g.attack + g.hold + g.decay;
    const int n = 96;
    for (int i = 0; i <= n; ++i) {
        const double tau = total * i / n;
        const double t = g.start + tau;
        // At tau = total the envelope is back to 0; at 0 it starts from 0.
        c.points.push_back(
            {t, g.strength.scalarAt(t) * fields::gustEnvelope(g, std::min(tau, total - 1e-12))});
    }
    c.points.front()[1] = 0.0;
    c.points.back()[1] = 0.0;
    return c;
}

} // namespace

SliceOverlays sceneOverlays(const fields::Scene& scene, double t) {
    SliceOverlays o;
    const fields::Windicator w = scene.windicator.value_or(fields::Windicator{});
    const fields::Vec3 dir = fields::windDirectionAt(w, t);
    if (scene.windicator) {
        o.windicator.present = true;
        o.windicator.direction = {dir[0], dir[1], dir[2]};
        o.windicator.speed = w.speed.scalarAt(t);
    }
    TimelineOverlay& tl = o.timeline;
    // Shot time, as $t and the keys see it (scene.time_zero: frames 1001-1048 are 0-1.96 s).
    fields::SceneSettings st = scene.settings;
    if (!(st.fps > 0)) st.fps = 24.0;
    tl.sceneStart = st.frameTime(st.frameStart);
    tl.sceneEnd = st.frameTime(st.frameEnd);
    tl.t0 = std::min({tl.sceneStart, t, 0.0});
    tl.t1 = std::max(tl.sceneEnd, t);
    for (size_t i = 0; i < scene.gusts.size(); ++i) {
        const fields::Gust& g = scene.gusts[i];
        const std::string label = g.name.empty() ? "gust " + std::to_string(i + 1) : g.name;
        tl.gusts.push_back(gustCurve(g, label));
        tl.t0 = std::min(tl.t0, g.start);
        tl.t1 = std::max(tl.t1, g.start + g.attack + g.hold + g.decay);
        if (g.travelSpeed > 0 && (dir[0] != 0 || dir[1] != 0 || dir[2] != 0)) {
            GustBand band;
            band.label = label;
            band.direction = {dir[0], dir[1], dir[2]};
            band.front = (t - g.start) * g.travelSpeed;
            band.tail = (t - g.start - (g.attack + g.hold + g.decay)) * g.travelSpeed;
            o.gusts.push_back(band);
        }
    }
    tl.present = !scene.gusts.empty() || (scene.windicator && w.speed.isKeyed());
    if (scene.windicator) {
        tl.windicatorSpeed.label = "windicator";
        const int n = 240;
        for (int i = 0; i <= n; ++i) {
            const double s = tl.t0 + (tl.t1 - tl.t0) * i / n;
            tl.windicatorSpeed.points.push_back({s, w.speed.scalarAt(s)});
        }
    }
    return o;
}

void parseObjGeometry(std::istream& in, GeometryOverlay& out) {
    auto index = [&](const std::string& word) {
        const int i = std::atoi(word.c_str()); // "7", "7/1/2": the vertex
        return i > 0 ? i - 1 : static_cast<int>(out.points.size()) + i;
    };
    for (std::string line; std::getline(in, line);) {
        std::istringstream words(line);
        std::string tag;
        words >> tag;
        if (tag == "v") {
            std::array<double, 3> p{};
            words >> p[0] >> p[1] >> p[2];
            out.points.push_back(p);
        } else if (tag == "f") {
            std::vector<int> poly;
            for (std::string w; words >> w;) poly.push_back(index(w));
            for (size_t k = 1; k + 1 < poly.size(); ++k)
                out.triangles.push_back({poly[0], poly[k], poly[k + 1]});
        } else if (tag == "l") {
            std::vector<int> line;
            for (std::string w; words >> w;) line.push_back(index(w));
            out.polylines.push_back(std::move(line));
        }
    }
}

bool loadFrameGeometry(const std::string& path, GeometryOverlay& out, std::string& error) {
    out = GeometryOverlay{};
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".obj") {
        std::ifstream in(path);
        if (!in) {
            error = path + ": cannot read: no such file (run gale sim first?)";
            return false;
        }
        parseObjGeometry(in, out);
        return true;
    }
    io::PointSet ps;
    if (io::IoError e = io::readPoints(path, ps)) {
        error = e.render();
        return false;
    }
    const int x = ps.find("x"), y = ps.find("y"), z = ps.find("z"), strand = ps.find("strand");
    if (x < 0 || y < 0 || z < 0) {
        error = path + ": no x, y, z columns";
        return false;
    }
    for (size_t i = 0; i < ps.size(); ++i)
        out.points.push_back({ps.columns[x][i], ps.columns[y][i], ps.columns[z][i]});
    for (const std::vector<int>& f : ps.faces)
        for (size_t k = 1; k + 1 < f.size(); ++k) out.triangles.push_back({f[0], f[k], f[k + 1]});
    if (strand >= 0)
        for (size_t i = 0; i < ps.size(); ++i) {
            if (i == 0 || ps.columns[strand][i] != ps.columns[strand][i - 1])
                out.polylines.emplace_back();
            out.polylines.back().push_back(static_cast<int>(i));
        }
    return true;
}

} // namespace gale::viz
