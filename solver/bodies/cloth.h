// Cloth: a triangle mesh with Baraff–Witkin stretch/shear, Bergou quadratic bending,
// stiffness-proportional (Rayleigh) damping, gravity, and per-triangle lift/drag from the wind
// sampled at the vertices. Masses are lumped by area (each triangle gives σA/3 to a corner).
#pragma once

#include "solver/bodies/body.h"
#include "solver/bodies/elastic.h"
#include "solver/mesh/mesh.h"

namespace gale::solver {

struct ClothMaterial {
    double density = 0.1;              // σ, kg/m² (not animatable)
    fields::Param stretch{2000.0};     // k_s, N/m
    fields::Param shear{200.0};        // k_sh, N/m
    fields::Param bend{0.001};         // k_b, N·m
    fields::Param damping{0.01};       // β, s: damping force −β K v (K: membrane + bending)
    PaintedParam lift;                 // C_L (value × map)
    PaintedParam drag;                 // C_D
    AeroModel aeroModel = AeroModel::Frozen;
    // Bending rest angles: false — flat (Bergou et al.); true — the rest mesh's own dihedral
    // angles (rest_shape = "mesh", elastic.h setHingeRestShape).
    bool curvedRest = false;
    ClothMaterial() {
        lift.value = fields::Param(0.3);
        drag.value = fields::Param(1.0);
    }
};

class Cloth : public Body {
public:
    // `start` (optional, same size as the mesh) is the initial shape when it differs from rest.
    Cloth(std::string name, TriMesh mesh, ClothMaterial material, const VecX* start = nullptr);

    const TriMesh& mesh() const { return mMesh; }
    const ClothMaterial& material() const { return mMat; }
    ClothMaterial& material() { return mMat; }
    int degenerateTriangles() const { return mDegenerate; }
    size_t hingeCount() const { return mHinges.size(); }

    bool feelsWind() const override { return !mMat.lift.alwaysZero() || !mMat.drag.alwaysZero(); }
    const char* kind() const override { return "cloth"; }
    const std::vector<std::array<int, 3>>* collisionTriangles() const override {
        return &mMesh.triangles;
    }

protected:
    void couplings(std::vector<std::pair<int, int>>& pairs) const override;
    void addForces(const ForceInput& in, ForceOutput& out) override;

private:
    TriMesh mMesh;
    ClothMaterial mMat;
    std::vector<MembraneRest> mMembrane;
    std::vector<std::array<int, 9>> mTriSlots; // matrix slot of (corner a, corner b), a*3+b
    std::vector<HingeStencil> mHinges;
    std::vector<HingeRest> mHingeRest;
    std::vector<int> mBendSlots;    // matrix slots the hinges touch
    std::vector<double> mBendCoef;  // per slot: Σ over hinges of scale·k_a·k_b (bending Hessian / k_b)
    std::vector<double> mTriLift, mTriDrag; // mean painted map value per triangle (or empty)
    // Parallel assembly (built on the first addForces): blocks of triangles and of hinges, no
    // two blocks of a colour sharing a vertex (types.h).
    ColouredBlocks mTriBlocks, mHingeBlocks;
    std::vector<double> mTriEnergy, mHingeEnergy; // per element, summed in element order
    int mDegenerate = 0;
    bool mCurved = false; // some hinge has a non-flat rest shape
};

} // namespace gale::solver
