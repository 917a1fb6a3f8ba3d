// Hair: strands as chains of stretch springs with discrete bending, pinned roots, and
// cross-flow aerodynamics (normal and tangential drag) per segment. Masses are lumped from the
// linear density λ = ρ π r² (half of each segment to either end).
#pragma once

#include "solver/bodies/body.h"
#include "solver/bodies/elastic.h"

#include <map>

#include <string>
#include <vector>

namespace gale::solver {

struct Strands {
    std::vector<double> positions; // 3 per vertex; each strand's vertices root first
    std::vector<int> offsets{0};   // strand s holds vertices [offsets[s], offsets[s+1])
    std::map<std::string, std::vector<double>> attributes; // per-vertex scalars (painted maps)

    size_t strandCount() const { return offsets.size() - 1; }
    size_t vertexCount() const { return positions.size() / 3; }
};

// nu × nv straight strands with roots on a grid of size width × depth (m) around `origin` in the
// plane spanned by axisU, axisV, each `length` m long with `segments` segments along `dir`.
Strands makeStrandGrid(const Vec3& origin, double width, double depth, int nu, int nv, double length,
                       int segments, const Vec3& axisU = Vec3::UnitX(), const Vec3& axisV = Vec3::UnitZ(),
                       const Vec3& dir = -Vec3::UnitY());

// Reads strands from a PLY or CSV point file whose vertices carry an integer `strand` column;
// consecutive vertices with the same id form a strand, root first. Strands of fewer than two
// vertices are dropped. False with `error` on failure.
bool loadStrands(const std::string& path, Strands& out, std::string& error);

struct HairMaterial {
    double radius = 4e-5;          // m (diameter d = 2r sets the drag area)
    double density = 1300.0;       // kg/m³ of the fibre
    fields::Param stretch{500.0};  // EA, N: spring k = EA / L per segment
    fields::Param bend{1e-4};      // EI, N·m²
    fields::Param damping{0.01};   // β, s: damping force −β K v
    PaintedParam dragNormal;       // C_n
    PaintedParam dragTangent;      // C_t
    bool rootPinned = true;
    // Bending rest shape: false — straight; true — the strand's own polyline (a curl; elastic.h
    // strandBendTarget).
    bool curledRest = false;
    HairMaterial() {
        dragNormal.value = fields::Param(1.2);
        dragTangent.value = fields::Param(0.05);
    }
};

class Hair : public Body {
public:
    Hair(std::string name, Strands strands, HairMaterial material);

    const Strands& strands() const { return mStrands; }
    bool feelsWind() const override {
        return !mMat.dragNormal.alwaysZero() || !mMat.dragTangent.alwaysZero();
    }
    const char* kind() const override { return "hair"; }

protected:
    void couplings(std::vector<std::pair<int, int>>& pairs) const override;
    void addForces(const ForceInput& in, ForceOutput& out) override;

private:
    struct Segment {
        int a, b;
        double rest;
    };
    struct Bend {
        int v[3];
        std::array<double, 3> w;
        double invLength; // 1 / L̄
        Vec3 restD = Vec3::Zero();            // d at the rest shape (zero: straight)
        Vec3 restTangent = Vec3::UnitX();     // unit rest direction of segment i−1
    };
    Strands mStrands;
    HairMaterial mMat;
    std::vector<Segment> mSegments;
    std::vector<std::array<int, 4>> mSegSlots;
    std::vector<Bend> mBends;
    std::vector<std::array<int, 9>> mBendSlots;
    std::vector<double> mSegCn, mSegCt; // painted map means per segment (or empty)
};

} // namespace gale::solver
