// gale.Scene, gale.Simulation and gale.Frame: a scene file loaded with `set` overrides (the
// dotted paths of `gale sim --set`), its wind sampled on a grid into numpy, and its cloth and
// hair simulated frame by frame through run/sim_run.h, the loop `gale sim` runs, so the frames
// are the same. The GIL is released while sampling and stepping.
#include "python/module.h"

#include "fields/expression_field.h"
#include "fields/grid_sample.h"
#include "run/sim_json.h"
#include "run/sim_run.h"
#include "scene/load.h"

#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <optional>

namespace gale::python {

namespace {

// A `set` value as the text `--set KEY=VALUE` takes: numbers, booleans, [a, b, c] lists, words.
std::string setText(const std::string& key, const py::handle& v) {
    if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
    if (py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v)) {
        const double d = v.cast<double>();
        if (!std::isfinite(d)) raise(ErrorKind::Argument, "set[\"" + key + "\"] must be finite");
        return py::str(py::repr(v));
    }
    if (py::isinstance<py::str>(v)) return v.cast<std::string>();
    if (py::isinstance<py::sequence>(v)) {
        std::string s = "[";
        bool firstItem = true;
        for (py::handle item : v) {
            s += (firstItem ? "" : ", ") + setText(key, item);
            firstItem = false;
        }
        return s + "]";
    }
    raise(ErrorKind::Argument, "set[\"" + key +
                                   "\"] must be a number, a bool, a string or a list, not " +
                                   std::string(py::str(py::type::of(v).attr("__name__"))));
}

std::vector<std::string> setList(const py::object& sets) {
    std::vector<std::string> out;
    if (sets.is_none()) return out;
    if (!py::isinstance<py::dict>(sets))
        raise(ErrorKind::Argument, "set must be a dict {\"dotted.key\": value}");
    for (auto item : py::reinterpret_borrow<py::dict>(sets)) {
        const std::string key = py::str(item.first);
        out.push_back(key + "=" + setText(key, item.second));
    }
    return out;
}

[[noreturn]] void raiseRun(const run::RunError& e) {
    const std::string text = e.text();
    const std::string trimmed =
        !text.empty() && text.back() == '\n' ? text.substr(0, text.size() - 1) : text;
    raise(e.kind == run::RunError::Io        ? ErrorKind::Io
          : e.kind == run::RunError::Numeric ? ErrorKind::Simulation
                                             : ErrorKind::Scene,
          trimmed);
}

struct Frame {
    int frame = 0;
    double time = 0.0;
    py::object stats;   // dict: run.json's entry for the frame
    py::dict positions; // object name -> (n, 3) float64
};

class Scene;

class Simulation {
public:
    Simulation(std::unique_ptr<run::SimRun> sim) : mSim(std::move(sim)), mNext(mSim->first()) {}
    Frame next() {
        if (mFailed || mNext > mSim->last()) throw py::stop_iteration();
        solver::FrameStats stats;
        if (mNext == mSim->first()) {
            // A range after the scene's first frame starts from the simulated state there
            // (run/sim_run.h, the run-up), as `gale sim --frames` does.
            bool ranUp = true;
            {
                py::gil_scoped_release release;
                ranUp = mSim->runUp({}, stats);
            }
            if (ranUp) stats = mSim->initialFrame();
        } else {
            py::gil_scoped_release release;
            stats = mSim->advance(mNext);
        }
        const std::string js = run::frameJson(stats);
        if (stats.failed) {
            mFailed = true;
            py::object type = errorType(ErrorKind::Simulation);
            py::object err = type(
                "frame " + std::to_string(mNext) +
                ": the run failed numerically (non-finite state that halving the substep could "
                "not fix); .stats holds the frame's stats");
            err.attr("stats") = py::module_::import("json").attr("loads")(js);
            PyErr_SetObject(type.ptr(), err.ptr());
            throw py::error_already_set();
        }
        Frame f;
        f.frame = stats.frame;
        f.time = stats.time;
        f.stats = py::module_::import("json").attr("loads")(js);
        for (const auto& b : mSim->world().bodies()) {
            const size_t n = b->vertexCount();
            py::array_t<double> x({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(3)});
            std::copy(b->positions().data(), b->positions().data() + 3 * n, x.mutable_data());
            f.positions[py::str(b->name())] = x;
        }
        ++mNext;
        return f;
    }
    py::dict settings() const {
        return py::module_::import("json").attr("loads")(mSim->settings());
    }
    std::vector<std::string> warnings() const { return mSim->warnings(); }
    int first() const { return mSim->first(); }
    int last() const { return mSim->last(); }

private:
    std::unique_ptr<run::SimRun> mSim;
    int mNext;
    bool mFailed = false;
};

class Scene {
public:
    Scene(std::string path, const py::object& sets, std::vector<std::string> allowPaths)
        : mPath(std::move(path)), mSets(setList(sets)), mAllow(std::move(allowPaths)) {
        scene::SimScene sim;
        std::vector<scene::SceneError> errors;
        if (!gale::scene::loadSimScene(mPath, sim, errors, mSets)) {
            run::RunError e;
            e.kind = run::RunError::Input;
            for (const scene::SceneError& s : errors) {
                e.rendered += s.render() + '\n';
                if (s.io) e.kind = run::RunError::Io;
            }
            raiseRun(e);
        }
        mWind = sim.wind;
        std::string report;
        mField = fields::buildSceneField(mWind, runtime::Precision::Float, report, false, mAllow);
        if (!mField) {
            run::RunError e;
            e.kind = run::RunError::Input;
            e.rendered = report;
            raiseRun(e);
        }
        mBodies = sim.cloths.size() + sim.hairs.size();
    }

    py::array sample(const std::vector<double>& bounds, const py::object& resObj,
                     std::optional<double> t, std::optional<double> frame, int threads) const {
        if (bounds.size() != 6)
            raise(ErrorKind::Argument, "bounds must be (x0, y0, z0, x1, y1, z1), not " +
                                           std::to_string(bounds.size()) + " numbers");
        std::vector<int> res;
        try {
            if (py::isinstance<py::int_>(resObj))
                res = {resObj.cast<int>()};
            else
                res = resObj.cast<std::vector<int>>();
        } catch (const py::cast_error&) {
            raise(ErrorKind::Argument, "res must be a whole number N or (nx, ny, nz)");
        }
        if (res.size() != 1 && res.size() != 3)
            raise(ErrorKind::Argument, "res must be N or (nx, ny, nz)");
        if (threads < 0) raise(ErrorKind::Argument, "threads must not be negative (0: all)");
        // The grid `gale sample --bounds --res` makes: N cells along the longest side (cubic
        // voxels), or exactly (nx, ny, nz).
        for (double b : bounds)
            if (!std::isfinite(b)) raise(ErrorKind::Argument, "bounds must be finite numbers");
        io::GridSpec grid;
        std::string error;
        const std::array<double, 6> box{bounds[0], bounds[1], bounds[2],
                                        bounds[3], bounds[4], bounds[5]};
        if (!io::gridFromBounds(box, res, 0.0, grid, error)) raise(ErrorKind::Argument, error);
        if ((t && !std::isfinite(*t)) || (frame && !std::isfinite(*frame)))
            raise(ErrorKind::Argument, "t and frame must be finite numbers");
        fields::SampleTime when;
        when.fps = mWind.settings.fps;
        when.frameZero = mWind.settings.timeZero;
        when.time = t ? *t : frame ? mWind.settings.frameTime(*frame) : 0.0;
        fields::GridSampleOptions options;
        options.threads = threads;
        std::vector<float> out;
        fields::SampleStatus status;
        {
            py::gil_scoped_release release;
            status = fields::sampleGrid(*mField, grid, when, out, options);
        }
        if (!status.ok) raise(ErrorKind::Scene, mPath + ": " + status.message);
        py::array_t<float> a({static_cast<py::ssize_t>(grid.res[0]),
                              static_cast<py::ssize_t>(grid.res[1]),
                              static_cast<py::ssize_t>(grid.res[2]), static_cast<py::ssize_t>(3)});
        std::copy(out.begin(), out.end(), a.mutable_data());
        return a;
    }

    Simulation simulate(const py::object& frames, int threads) const {
        if (threads < 0) raise(ErrorKind::Argument, "threads must not be negative (0: all)");
        run::SimSetup setup;
        setup.scene = mPath;
        setup.sets = mSets;
        setup.allowPaths = mAllow;
        setup.threads = threads;
        if (!frames.is_none()) {
            std::vector<int> ab;
            try {
                ab = frames.cast<std::vector<int>>();
            } catch (const py::cast_error&) {
                raise(ErrorKind::Argument, "frames must be (first, last), two whole numbers");
            }
            if (ab.size() != 2 || ab[0] >= ab[1] || ab[1] - static_cast<long>(ab[0]) >= 100000)
                raise(ErrorKind::Argument,
                      "frames must be (first, last) with first < last, at most 100000 frames");
            setup.hasFrames = true;
            setup.first = ab[0];
            setup.last = ab[1];
        }
        auto sim = std::make_unique<run::SimRun>();
        std::string report;
        const run::RunError e = sim->load(setup, report);
        if (e) raiseRun(e);
        if (!report.empty()) py::module_::import("sys").attr("stderr").attr("write")(report);
        return Simulation(std::move(sim));
    }

    const std::string& path() const { return mPath; }
    double fps() const { return mWind.settings.fps; }
    py::tuple frameRange() const {
        return py::make_tuple(mWind.settings.frameStart, mWind.settings.frameEnd);
    }
    size_t bodies() const { return mBodies; }

private:
    std::string mPath;
    std::vector<std::string> mSets;
    std::vector<std::string> mAllow;
    fields::Scene mWind;
    fields::FieldPtr mField;
    size_t mBodies = 0;
};

} // namespace

void addScene(py::module_& m) {
    py::class_<Frame>(m, "Frame",
                      "One simulated frame: frame, time (s), stats (run.json's entry), positions")
        .def_readonly("frame", &Frame::frame)
        .def_readonly("time", &Frame::time)
        .def_readonly("stats", &Frame::stats)
        .def_readonly("positions", &Frame::positions, "object name -> (n, 3) float64 positions (m)")
        .def("__repr__",
             [](const Frame& f) { return "<gale.Frame " + std::to_string(f.frame) + ">"; });
    py::class_<Simulation>(m, "Simulation",
                           "Frames of a simulation, one per iteration (Scene.simulate)")
        .def(
            "__iter__", [](Simulation& s) -> Simulation& { return s; },
            py::return_value_policy::reference_internal)
        .def("__next__", &Simulation::next)
        .def_property_readonly("settings", &Simulation::settings,
                               "run.json's settings: the scene as resolved")
        .def_property_readonly("warnings", &Simulation::warnings,
                               "run.json's warnings: likely mistakes in the scene, "
                               "'file:line:col: message' each")
        .def_property_readonly(
            "frames", [](const Simulation& s) { return py::make_tuple(s.first(), s.last()); });
    py::class_<Scene>(m, "Scene",
                      "A scene file (.toml) with `set` overrides by dotted path, as gale sim --set")
        .def(py::init<std::string, py::object, std::vector<std::string>>(), py::arg("path"),
             py::kw_only(), py::arg("set") = py::none(),
             py::arg("allow_paths") = std::vector<std::string>())
        .def("sample", &Scene::sample, py::kw_only(), py::arg("bounds"), py::arg("res") = 32,
             py::arg("t") = py::none(), py::arg("frame") = py::none(), py::arg("threads") = 0,
             "The wind at the cell centres of a grid over bounds (x0, y0, z0, x1, y1, z1) with res "
             "cells per "
             "axis (N or (nx, ny, nz)): (nx, ny, nz, 3) float32, m/s")
        .def("simulate", &Scene::simulate, py::kw_only(), py::arg("frames") = py::none(),
             py::arg("threads") = 1,
             "Simulates the cloth and hair frame by frame from the initial state at frames[0]: an "
             "iterator of "
             "gale.Frame, the same frames as `gale sim`")
        .def_property_readonly("path", &Scene::path)
        .def_property_readonly("fps", &Scene::fps)
        .def_property_readonly("frame_range", &Scene::frameRange);
}

} // namespace gale::python
