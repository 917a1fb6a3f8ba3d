// Cloth forces: membrane (Baraff–Witkin), bending (Bergou et al. 2006), Rayleigh damping and
// aerodynamics (Wilson et al. 2014), assembled into f, K v and M + hD + h²K.
//
// Aerodynamics per triangle: wind w̄ and cloth velocity ū are the means over its corners,
// v = w̄ − ū, F from aeroTriangle(), split F/3 per corner. Since ∂v/∂u_j = −I/3, the damping
// matrix of the triangle contributes D/9 to each of its 9 corner blocks.
#include "solver/cloth.h"

#include <cmath>

namespace gale::solver {

namespace {
VecX flatten(const std::vector<double>& p) { return Eigen::Map<const VecX>(p.data(), p.size()); }
} // namespace

Cloth::Cloth(std::string name, TriMesh mesh, ClothMaterial material, const VecX* start)
    : Body(std::move(name), flatten(mesh.positions)), mMesh(std::move(mesh)), mMat(std::move(material)) {
    const size_t nt = mMesh.triangles.size();
    const double* x = mMesh.positions.data();
    mMembrane.resize(nt);
    for (size_t e = 0; e < nt; ++e) {
        const auto& t = mMesh.triangles[e];
        Vec3 uv[3];
        Vec3 p[3] = {vec3At(x, t[0]), vec3At(x, t[1]), vec3At(x, t[2])};
        if (mMesh.uvIsMaterialSpace && mMesh.uv.size() == 2 * mMesh.vertexCount()) {
            for (int k = 0; k < 3; ++k) uv[k] = Vec3(mMesh.uv[2 * t[k]], mMesh.uv[2 * t[k] + 1], 0.0);
        } else {
            materialCoordinates(p, Vec3::UnitX(), uv);
        }
        if (!makeMembraneRest(uv, mMembrane[e])) ++mDegenerate;
        // Lumped mass: σ A / 3 to each corner (A: the rest area in 3D).
        const double area = 0.5 * triangleCross(x, t).norm();
        if (std::isfinite(area))
            for (int k = 0; k < 3; ++k) mMass[t[k]] += mMat.density * area / 3.0;
    }
    mHinges = meshHinges(mMesh.triangles);
    mHingeRest.resize(mHinges.size());
    for (size_t h = 0; h < mHinges.size(); ++h) {
        Vec3 p[4];
        for (int k = 0; k < 4; ++k) p[k] = vec3At(x, mHinges[h].v[k]);
        makeHingeRest(p, mHingeRest[h]);
    }
    auto triMean = [&](const std::vector<double>& map, std::vector<double>& out) {
        out.clear();
        if (map.size() != mMesh.vertexCount()) return;
        out.resize(nt);
        for (size_t e = 0; e < nt; ++e) {
            const auto& t = mMesh.triangles[e];
            out[e] = (map[t[0]] + map[t[1]] + map[t[2]]) / 3.0;
        }
    };
    triMean(mMat.lift.map, mTriLift);
    triMean(mMat.drag.map, mTriDrag);
    finishSetup(meshEdges(mMesh.triangles));
    mTriSlots.resize(nt);
    for (size_t e = 0; e < nt; ++e) {
        const auto& t = mMesh.triangles[e];
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) mTriSlots[e][3 * a + b] = matrix().slot(t[a], t[b]);
    }
    mHingeSlots.resize(mHinges.size());
    for (size_t h = 0; h < mHinges.size(); ++h)
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                mHingeSlots[h][4 * a + b] = matrix().slot(mHinges[h].v[a], mHinges[h].v[b]);
    if (start && start->size() == mX.size()) mX = *start;
}

void Cloth::couplings(std::vector<std::pair<int, int>>& pairs) const {
    for (const auto& t : mMesh.triangles)
        for (int a = 0; a < 3; ++a) pairs.push_back({t[a], t[(a + 1) % 3]});
    for (size_t h = 0; h < mHinges.size(); ++h) {
        if (!(mHingeRest[h].scale > 0.0)) continue;
        const auto& v = mHinges[h].v;
        pairs.push_back({v[2], v[3]}); // the only pair a triangle does not already couple
    }
}

void Cloth::addForces(const ForceInput& in, ForceOutput& out) {
    const double t = in.t, h = in.h;
    const double ks = mMat.stretch.scalarAt(t), ksh = mMat.shear.scalarAt(t);
    const double kb = mMat.bend.scalarAt(t), beta = mMat.damping.scalarAt(t);
    const double cK = h * h + h * beta; // scale of K in the matrix: h²K + h(βK)
    VecX& f = *out.f;
    VecX* kv = out.kv;
    BlockMatrix* A = out.A;
    const size_t nt = mMesh.triangles.size();

    // Membrane (stretch + shear) with Rayleigh damping f = −βKv.
    TriangleElastic te;
    for (size_t e = 0; e < nt; ++e) {
        const MembraneRest& rest = mMembrane[e];
        if (!(rest.area > 0.0)) continue;
        const auto& tri = mMesh.triangles[e];
        const Vec3 p[3] = {vec3At(in.x, tri[0]), vec3At(in.x, tri[1]), vec3At(in.x, tri[2])};
        membraneForces(rest, p, ks, ksh, te);
        out.elasticEnergy += te.energy;
        const Vec3 vel[3] = {vec3At(in.v, tri[0]), vec3At(in.v, tri[1]), vec3At(in.v, tri[2])};
        for (int a = 0; a < 3; ++a) {
            const Vec3 kva = te.K[a][0] * vel[0] + te.K[a][1] * vel[1] + te.K[a][2] * vel[2];
            f.segment<3>(3 * tri[a]) += te.f[a] - beta * kva;
            if (kv) kv->segment<3>(3 * tri[a]) += kva;
        }
        if (A)
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) A->addBlock(mTriSlots[e][3 * a + b], te.K[a][b], cK);
    }

    // Bending: constant Hessian Q = c k kᵀ ⊗ I per hinge.
    if (kb != 0.0)
        for (size_t hi = 0; hi < mHinges.size(); ++hi) {
            const HingeRest& r = mHingeRest[hi];
            if (!(r.scale > 0.0)) continue;
            const auto& v = mHinges[hi].v;
            const double c = kb * r.scale;
            Vec3 s = Vec3::Zero(), sv = Vec3::Zero();
            for (int a = 0; a < 4; ++a) {
                s += r.k[a] * vec3At(in.x, v[a]);
                sv += r.k[a] * vec3At(in.v, v[a]);
            }
            out.elasticEnergy += 0.5 * c * s.squaredNorm();
            for (int a = 0; a < 4; ++a) {
                f.segment<3>(3 * v[a]) -= c * r.k[a] * (s + beta * sv);
                if (kv) kv->segment<3>(3 * v[a]) += c * r.k[a] * sv;
            }
            if (A)
                for (int a = 0; a < 4; ++a)
                    for (int b = 0; b < 4; ++b)
                        A->addDiagonal(mHingeSlots[hi][4 * a + b], cK * c * r.k[a] * r.k[b]);
        }

    // Aerodynamics.
    if (!in.wind) return;
    const double cl0 = mMat.lift.at(t), cd0 = mMat.drag.at(t);
    if (cl0 == 0.0 && cd0 == 0.0) return;
    const bool paintL = !mTriLift.empty(), paintD = !mTriDrag.empty();
    for (size_t e = 0; e < nt; ++e) {
        const auto& tri = mMesh.triangles[e];
        const Vec3 areaNormal = 0.5 * triangleCross(in.x, tri);
        const Vec3 wind = (vec3At(in.wind, tri[0]) + vec3At(in.wind, tri[1]) + vec3At(in.wind, tri[2])) / 3.0;
        const Vec3 u = (vec3At(in.v, tri[0]) + vec3At(in.v, tri[1]) + vec3At(in.v, tri[2])) / 3.0;
        const double cl = std::max(0.0, paintL ? cl0 * mTriLift[e] : cl0);
        const double cd = std::max(0.0, paintD ? cd0 * mTriDrag[e] : cd0);
        const AeroResult r =
            aeroTriangle(wind - u, areaNormal, in.airDensity, cl, cd, mMat.aeroModel, in.aeroJacobian);
        out.clamped += r.clamped ? 1 : 0;
        const Vec3 f3 = r.force / 3.0;
        for (int a = 0; a < 3; ++a) f.segment<3>(3 * tri[a]) += f3;
        if (A && in.aeroJacobian != AeroJacobian::None)
            for (int s = 0; s < 9; ++s) A->addBlock(mTriSlots[e][s], r.damping, h / 9.0);
    }
}

} // namespace gale::solver
