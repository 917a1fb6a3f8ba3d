// The live page's JSON documents (json.h), built with nlohmann::json.
#include "live/json.h"

#include "viz/plot_geometry.h"

#include <cmath>

namespace gale::live {

using nlohmann::json;

namespace {

double round4(double v) {
    return std::isfinite(v) ? std::round(v * 1e4) / 1e4 : 0.0;
}

template <class T>
json rounded(const std::vector<T>& v) {
    json a = json::array();
    a.get_ref<json::array_t&>().reserve(v.size());
    for (const T& x : v) a.push_back(round4(static_cast<double>(x)));
    return a;
}

json vec(const std::array<double, 3>& v) {
    return json::array({v[0], v[1], v[2]});
}

// viz::viridis at 33 even stops: the page interpolates between them.
json colormap() {
    json m = json::array();
    for (int i = 0; i <= 32; ++i) {
        const viz::Rgb c = viz::viridis(i / 32.0);
        m.push_back({round4(c.r), round4(c.g), round4(c.b)});
    }
    return m;
}

json valueJson(const std::vector<double>& v) {
    return v.size() == 1 ? json(v[0]) : json(v);
}

} // namespace

json stateJson(const Project& p, double time) {
    json s;
    s["input"] = p.input();
    s["scene"] = p.isScene();
    s["ok"] = p.ok();
    s["files"] = p.files();
    s["time"] = time;
    s["fps"] = p.fps();
    s["timeZero"] = p.timeZero();
    s["frames"] = json::array({p.frameStart(), p.frameEnd()});
    json diags = json::array();
    for (const Diagnostic& d : p.diagnostics())
        diags.push_back({{"file", d.file},
                         {"line", d.line},
                         {"col", d.col},
                         {"severity", d.severity},
                         {"message", d.message},
                         {"text", d.text}});
    s["diagnostics"] = diags;
    json params = json::array();
    for (const LiveParam& lp : p.params()) {
        const ParamLiteral& l = lp.literal;
        json j = {{"name", l.name},
                  {"value", valueJson(l.value)},
                  {"file", lp.file},
                  {"line", l.line},
                  {"col", l.col},
                  {"field", lp.field},
                  {"declaredIn", lp.declaredIn},
                  {"editable", lp.editable},
                  {"integer", l.integer},
                  {"doc", l.doc},
                  {"width", l.value.size()}};
        if (l.hasRange) {
            j["min"] = l.min;
            j["max"] = l.max;
        } else {
            j["min"] = nullptr;
            j["max"] = nullptr;
        }
        params.push_back(j);
    }
    s["params"] = params;
    json ramps = json::array();
    for (const LiveRamp& r : p.ramps()) {
        json pts = json::array();
        for (const RampPoint& q : r.literal.points)
            pts.push_back(
                {{"position", q.position}, {"value", valueJson(q.value)}, {"interp", q.interp}});
        ramps.push_back({{"id", r.id},
                         {"function", r.literal.function},
                         {"file", r.file},
                         {"line", r.literal.line},
                         {"col", r.literal.col},
                         {"points", pts}});
    }
    s["ramps"] = ramps;
    return s;
}

json geometryJson(const viz::GeometryOverlay& g) {
    json pts = json::array(), tris = json::array(), lines = json::array();
    for (const auto& p : g.points)
        for (double c : p) pts.push_back(round4(c));
    for (const auto& t : g.triangles)
        for (int i : t) tris.push_back(i);
    for (const auto& l : g.polylines) lines.push_back(l);
    return {{"label", g.label}, {"points", pts}, {"triangles", tris}, {"polylines", lines}};
}

json sceneJson(const Project& p) {
    json rest = json::array(), colliders = json::array();
    for (const viz::GeometryOverlay& g : p.restGeometry()) rest.push_back(geometryJson(g));
    for (const ColliderShape& c : p.colliders()) {
        json j = {{"name", c.name},    {"shape", c.shape},        {"a", vec(c.a)},
                  {"b", vec(c.b)},     {"normal", vec(c.normal)}, {"radius", c.radius},
                  {"moving", c.moving}};
        if (!c.mesh.points.empty()) j["mesh"] = geometryJson(c.mesh);
        colliders.push_back(j);
    }
    const viz::Box3& b = p.box();
    return {
        {"box", {{"lo", vec(b.lo)}, {"hi", vec(b.hi)}}}, {"rest", rest}, {"colliders", colliders}};
}

json collidersJson(const Project& p, double t) {
    json colliders = json::array();
    for (const ColliderShape& c : p.collidersAt(t)) {
        json j = {{"name", c.name},    {"shape", c.shape},        {"a", vec(c.a)},
                  {"b", vec(c.b)},     {"normal", vec(c.normal)}, {"radius", c.radius},
                  {"moving", c.moving}};
        if (c.moving) {
            json pts = json::array();
            for (const auto& q : c.mesh.points)
                for (double x : q) pts.push_back(round4(x));
            j["points"] = pts;
        }
        colliders.push_back(j);
    }
    return {{"t", t}, {"colliders", colliders}};
}

json fieldJson(const FieldFrame& f, const viz::SliceOverlays& o) {
    const viz::Slice& s = f.slice;
    json slice = {{"nu", s.nu},
                  {"nv", s.nv},
                  {"bounds", s.bounds},
                  {"uAxis", s.uAxis},
                  {"vAxis", s.vAxis},
                  {"axis", s.normalAxis},
                  {"plane", s.planeValue},
                  {"speed", rounded(f.speed.speed)},
                  {"max", f.speed.max},
                  {"top", f.speed.top},
                  {"colormap", colormap()}};
    json arrows = {{"n", f.arrows.n},
                   {"positions", rounded(f.arrows.positions)},
                   {"velocities", rounded(f.arrows.velocities)},
                   {"max", f.arrows.maxSpeed}};
    json lines = json::array();
    for (const viz::Streamline& l : f.streamlines) {
        std::vector<float> flat;
        flat.reserve(3 * l.points.size());
        for (const auto& p : l.points) flat.insert(flat.end(), p.begin(), p.end());
        lines.push_back({{"points", rounded(flat)}, {"speed", rounded(l.speed)}});
    }
    json gusts = json::array();
    for (const viz::GustBand& g : o.gusts)
        gusts.push_back({{"label", g.label},
                         {"direction", vec(g.direction)},
                         {"front", g.front},
                         {"tail", g.tail}});
    json curves = json::array();
    for (const auto& c : o.timeline.gusts)
        curves.push_back({{"label", c.label}, {"points", c.points}});
    json overlays = {{"windicator",
                      {{"present", o.windicator.present},
                       {"direction", vec(o.windicator.direction)},
                       {"speed", o.windicator.speed}}},
                     {"gusts", gusts},
                     {"timeline",
                      {{"present", o.timeline.present},
                       {"t0", o.timeline.t0},
                       {"t1", o.timeline.t1},
                       {"sceneStart", o.timeline.sceneStart},
                       {"sceneEnd", o.timeline.sceneEnd},
                       {"gusts", curves},
                       {"windicator", o.timeline.windicatorSpeed.points}}}};
    return {{"slice", slice},
            {"arrows", arrows},
            {"streamlines", lines},
            {"overlays", overlays},
            {"times",
             {{"slice", f.times.slice},
              {"arrows", f.times.arrows},
              {"streamlines", f.times.streamlines}}}};
}

std::string jsonText(const json& j) {
    return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string errorJson(const std::string& message) {
    return jsonText(json{{"error", message}});
}

} // namespace gale::live
