// The rigs' overlays of a scene at a time: the timeline spans the shot in shot time (time_zero),
// and the windicator and gusts are drawn where their keys put them.
#include "viz/overlays.h"

#include <catch2/catch.hpp>

using namespace gale;

TEST_CASE("overlays: the timeline spans the shot in shot time", "[viz][overlays]") {
    fields::Scene scene;
    scene.settings.fps = 24.0;
    scene.windicator = fields::Windicator{};
    scene.windicator->speed =
        fields::Param::keyed({0.0, 1.5}, {{3.0}, {6.0}}, fields::KeyInterp::Linear);
    SECTION("studio frame numbers: frames 1001-1048, time_zero = 1001") {
        scene.settings.frameStart = 1001;
        scene.settings.frameEnd = 1048;
        scene.settings.timeZero = 1001;
        const viz::SliceOverlays o = viz::sceneOverlays(scene, 0.5);
        REQUIRE(o.timeline.present);
        CHECK(o.timeline.sceneStart == Approx(0.0).margin(1e-12));
        CHECK(o.timeline.sceneEnd == Approx(47.0 / 24.0));
        CHECK(o.timeline.t0 == Approx(0.0).margin(1e-12));
        CHECK(o.timeline.t1 == Approx(47.0 / 24.0)); // not 0-43.7 s (frames over fps)
        // The keyed speed across it, from the keys: 3 m/s at the start, 6 from 1.5 s.
        REQUIRE(o.timeline.windicatorSpeed.points.size() > 2);
        CHECK(o.timeline.windicatorSpeed.points.front()[1] == Approx(3.0));
        CHECK(o.timeline.windicatorSpeed.points.back()[1] == Approx(6.0));
    }
    SECTION("no time_zero: frame F ends at F / fps") {
        scene.settings.frameStart = 1;
        scene.settings.frameEnd = 48;
        const viz::SliceOverlays o = viz::sceneOverlays(scene, 0.5);
        CHECK(o.timeline.sceneStart == Approx(1.0 / 24.0));
        CHECK(o.timeline.sceneEnd == Approx(2.0));
    }
}
