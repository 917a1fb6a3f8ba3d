// Cloth forces: membrane (Baraff–Witkin), bending (Bergou et al. 2006), Rayleigh damping and
// aerodynamics (Wilson et al. 2014), assembled into f, K v and M + hD + h²K.
//
// Aerodynamics per triangle: wind w̄ and cloth velocity ū are the means over its corners,
// v = w̄ − ū, F from aeroTriangle(), split F/3 per corner. Since ∂v/∂u_j = −I/3, the damping
// matrix of the triangle contributes D/9 to each of its 9 corner blocks.
#include "solver/bodies/cloth.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <atomic>
#include <cmath>

namespace gale::solver {

namespace {
// Meshes with fewer elements assemble on the calling thread alone (the same bits).
constexpr size_t kParallelElements = 2048;

// Elements (triangles, hinges) per block of the parallel assembly order.
constexpr int kElementBlock = 128;

// The parallel assembly order (types.h, ColouredBlocks) of elements with K corners:
// consecutive blocks of elements, two blocks neighbours when they share a vertex, so that the
// blocks of one colour write disjoint vertices and matrix slots.
template <size_t K, class Corners>
ColouredBlocks colourElements(size_t count, size_t vertices, Corners corners) {
    const int n = static_cast<int>(count);
    std::vector<std::vector<int>> blocksAt(vertices); // vertex → the blocks touching it
    for (int e = 0; e < n; ++e) {
        const std::array<int, K>& c = corners(e);
        for (int v : c)
            if (blocksAt[v].empty() || blocksAt[v].back() != e / kElementBlock)
                blocksAt[v].push_back(e / kElementBlock);
    }
    std::vector<std::vector<int>> near((n + kElementBlock - 1) / kElementBlock);
    for (const std::vector<int>& bs : blocksAt)
        for (int b : bs) near[b].insert(near[b].end(), bs.begin(), bs.end());
    for (std::vector<int>& nb : near) {
        std::sort(nb.begin(), nb.end());
        nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    }
    return colourBlocks(n, kElementBlock, near);
}

VecX flatten(const std::vector<double>& p) { return Eigen::Map<const VecX>(p.data(), p.size()); }

// Adds a triangle's nine blocks (a, b) = cK·K_ab + D9 to A: K from the membrane factors m (null:
// no membrane), K_ab = a_a a_b S_u + b_a b_b S_v + c s_a s_bᵀ (elastic.h); D9 = (h/9)·D is
// symmetric. Only the shear term differs between (a, b) and (b, a) = (a, b)ᵀ.
void addTriangleBlocks(BlockMatrix& A, const int slot[9], const MembraneFactors* m, double cK,
                       const Mat3& D9) {
    if (!m) {
        for (int k = 0; k < 9; ++k) A.addBlock(slot[k], D9);
        return;
    }
    for (int a = 0; a < 3; ++a) {
        const Vec3 sa = (cK * m->shear) * m->s[a];
        for (int b = a; b < 3; ++b) {
            const double cu = cK * m->a[a] * m->a[b], cv = cK * m->b[a] * m->b[b];
            const Vec3& sb = m->s[b];
            Mat3 kab, kba;
            for (int c = 0; c < 3; ++c)
                for (int r = 0; r < 3; ++r) {
                    const double sym = cu * m->Su(r, c) + cv * m->Sv(r, c) + D9(r, c);
                    kab(r, c) = sym + sa[r] * sb[c];
                    kba(r, c) = sym + sb[r] * sa[c];
                }
            A.addBlock(slot[3 * a + b], kab);
            if (b != a) A.addBlock(slot[3 * b + a], kba);
        }
    }
}
// The PSD part of the symmetrised orientation Jacobian of one triangle (AeroOrientation):
// blocks K_ab = P C_b for every corner a, with C₁ = −[e₂]×, C₂ = [e₁]×, C₀ = −C₁ − C₂; the
// symmetric ½(K + Kᵀ) with its negative eigenvalues dropped (Teran et al. 2005's projection).
Mat3 crossMatrix(const Vec3& e) { // [e]× x = e × x
    Mat3 m;
    m << 0, -e.z(), e.y(), e.z(), 0, -e.x(), -e.y(), e.x(), 0;
    return m;
}

Mat9 orientationPsd(const AeroOrientation& c) {
    const Mat3 c1 = -crossMatrix(c.e2), c2 = crossMatrix(c.e1), c0 = -c1 - c2;
    const Mat3 pc[3] = {c.position * c0, c.position * c1, c.position * c2};
    Mat9 k;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) k.block<3, 3>(3 * a, 3 * b) = pc[b];
    const Mat9 sym = 0.5 * (k + k.transpose());
    Eigen::SelfAdjointEigenSolver<Mat9> eig(sym);
    if (eig.info() != Eigen::Success) return Mat9::Zero();
    const Eigen::Matrix<double, 9, 1> l = eig.eigenvalues().cwiseAbs();
    return eig.eigenvectors() * l.asDiagonal() * eig.eigenvectors().transpose();
}
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
        if (makeHingeRest(p, mHingeRest[h]) && mMat.curvedRest) setHingeRestShape(p, mHingeRest[h]);
        if (mHingeRest[h].bent.squaredNorm() > 0.0) mCurved = true;
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
    // The bending Hessian is constant up to k_b: per matrix slot (i, j), the sum over hinges of
    // scale·k_a·k_b (a, b the hinge corners at i, j), so a substep adds cK·k_b·coef·I per slot.
    std::vector<int> bendIndex(matrix().slotCount(), -1);
    for (size_t h = 0; h < mHinges.size(); ++h) {
        const HingeRest& r = mHingeRest[h];
        if (!(r.scale > 0.0)) continue;
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b) {
                const int slot = matrix().slot(mHinges[h].v[a], mHinges[h].v[b]);
                if (bendIndex[slot] < 0) {
                    bendIndex[slot] = static_cast<int>(mBendSlots.size());
                    mBendSlots.push_back(slot);
                    mBendCoef.push_back(0.0);
                }
                mBendCoef[bendIndex[slot]] += r.scale * r.k[a] * r.k[b];
            }
    }
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

    // Aerodynamics only when the body feels wind with a nonzero coefficient; its damping
    // matrix only for an implicit Jacobian.
    const double cl0 = in.wind ? mMat.lift.at(t) : 0.0, cd0 = in.wind ? mMat.drag.at(t) : 0.0;
    const bool aero = in.wind && !(cl0 == 0.0 && cd0 == 0.0);
    const bool aeroMatrix = aero && A && in.aeroJacobian != AeroJacobian::None;
    const bool paintL = !mTriLift.empty(), paintD = !mTriDrag.empty();

    // Per triangle: membrane (stretch + shear) with Rayleigh damping f = −βKv, and the
    // aerodynamic force F/3 per corner. Its 9 matrix blocks (a, b) get, in one write each,
    //   cK·K_ab + (h/9)·D.
    if (out.aero) out.aero->assign(aeroMatrix ? nt : 0, AeroCoupling{}); // one slot per triangle
    if (out.aeroOrientation)
        out.aeroOrientation->assign(aeroMatrix && out.aero ? nt : 0, AeroOrientation{});
    std::atomic<bool> skewedAll{false}; // any triangle with a skew part
    // Triangles in blocks, colour by colour (mTriBlocks), the blocks of a colour in parallel:
    // they share no vertex, so each vertex and slot receives its terms in the same order on any
    // number of threads; energies summed per triangle in triangle order.
    if (mTriBlocks.order.size() != nt)
        mTriBlocks = colourElements<3>(nt, vertexCount(), [&](int e) -> const std::array<int, 3>& {
            return mMesh.triangles[e];
        });
    mTriEnergy.resize(nt);
    const Mat3 zero = Mat3::Zero();
    std::atomic<int> clampedAll{0};
    auto triangles = [&](size_t s0, size_t s1) {
        MembraneFactors m;
        int clamped = 0;
        for (size_t s = s0; s < s1; ++s) {
            const size_t e = static_cast<size_t>(mTriBlocks.order[s]);
            const auto& tri = mMesh.triangles[e];
            const Vec3 p[3] = {vec3At(in.x, tri[0]), vec3At(in.x, tri[1]), vec3At(in.x, tri[2])};
            const Vec3 vel[3] = {vec3At(in.v, tri[0]), vec3At(in.v, tri[1]), vec3At(in.v, tri[2])};
            Vec3 f3 = Vec3::Zero(); // F/3 per corner
            Mat3 hD9;               // (h/9)·D
            bool withD = false;
            if (aero) {
                const Vec3 areaNormal = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]);
                const Vec3 wind =
                    (vec3At(in.wind, tri[0]) + vec3At(in.wind, tri[1]) + vec3At(in.wind, tri[2])) /
                    3.0;
                const Vec3 u = (vel[0] + vel[1] + vel[2]) / 3.0;
                const double cl = std::max(0.0, paintL ? cl0 * mTriLift[e] : cl0);
                const double cd = std::max(0.0, paintD ? cd0 * mTriDrag[e] : cd0);
                const AeroResult r = aeroTriangle(wind - u, areaNormal, in.airDensity, cl, cd,
                                                  mMat.aeroModel, in.aeroJacobian);
                clamped += r.clamped ? 1 : 0;
                f3 = r.force / 3.0;
                if (aeroMatrix) {
                    hD9 = (h / 9.0) * r.damping;
                    withD = true;
                    if (out.aero) {
                        AeroCoupling& c = (*out.aero)[e];
                        c = {{tri[0], tri[1], tri[2]}, hD9, (h / 9.0) * r.skewAxis};
                        if (in.aeroPosition && out.aeroOrientation) {
                            AeroOrientation& o = (*out.aeroOrientation)[e];
                            o.position = (-h * h / 6.0) * aeroTriangleAreaJacobian(
                                                              wind - u, areaNormal, in.airDensity,
                                                              cl, cd, mMat.aeroModel);
                            o.e1 = p[1] - p[0];
                            o.e2 = p[2] - p[0];
                            o.velocityRest = (h / 9.0) * aeroTriangleExactJacobian(
                                                             wind - u, areaNormal, in.airDensity,
                                                             cl, cd, mMat.aeroModel) -
                                             hD9;
                            if (A) {
                                o.psd = orientationPsd(o);
                                for (int a = 0; a < 3; ++a)
                                    for (int b = 0; b < 3; ++b)
                                        A->addBlock(mTriSlots[e][3 * a + b],
                                                    o.psd.block<3, 3>(3 * a, 3 * b));
                            }
                        }
                    }
                    if (r.skewAxis.squaredNorm() > 0.0) skewedAll.store(true, std::memory_order_relaxed);
                }
            }
            const bool membrane = membraneFactors(mMembrane[e], p, ks, ksh, m);
            mTriEnergy[e] = membrane ? m.energy : 0.0;
            if (membrane) {
                // (K v)_a = a_a S_u ẇ_u + b_a S_v ẇ_v + c (Σ_j s_j·v_j) s_a (elastic.h).
                const Vec3 Swu = m.Su * (m.a[0] * vel[0] + m.a[1] * vel[1] + m.a[2] * vel[2]);
                const Vec3 Swv = m.Sv * (m.b[0] * vel[0] + m.b[1] * vel[1] + m.b[2] * vel[2]);
                const double sv =
                    m.shear * (m.s[0].dot(vel[0]) + m.s[1].dot(vel[1]) + m.s[2].dot(vel[2]));
                for (int a = 0; a < 3; ++a) {
                    const Vec3 kva = m.a[a] * Swu + m.b[a] * Swv + sv * m.s[a];
                    f.segment<3>(3 * tri[a]) += m.f[a] - beta * kva + f3;
                    if (kv) kv->segment<3>(3 * tri[a]) += kva;
                }
            } else if (aero) {
                for (int a = 0; a < 3; ++a) f.segment<3>(3 * tri[a]) += f3;
            }
            if (A && (membrane || withD))
                addTriangleBlocks(*A, mTriSlots[e].data(), membrane ? &m : nullptr, cK,
                                  withD ? hD9 : zero);
        }
        if (clamped) clampedAll.fetch_add(clamped, std::memory_order_relaxed);
    };
    forEachColour(mTriBlocks, false, nt >= kParallelElements && arenaConcurrency() >= 2, triangles);
    out.clamped += clampedAll.load();
    double energy = 0.0; // (locals: `out` may alias f for all the compiler knows)
    for (size_t e = 0; e < nt; ++e) energy += mTriEnergy[e];
    out.skewed = out.skewed || skewedAll.load();

    // Bending: constant Hessian Q = c k kᵀ ⊗ I per hinge, c = k_b·scale; hinges in coloured
    // blocks like the triangles, energies summed per hinge in hinge order.
    if (kb != 0.0) {
        const size_t nh = mHinges.size();
        if (mHingeBlocks.order.size() != nh)
            mHingeBlocks =
                colourElements<4>(nh, vertexCount(),
                                  [&](int e) -> const std::array<int, 4>& { return mHinges[e].v; });
        mHingeEnergy.resize(nh);
        auto hinges = [&](size_t s0, size_t s1) {
            for (size_t q = s0; q < s1; ++q) {
                const size_t hi = static_cast<size_t>(mHingeBlocks.order[q]);
                const HingeRest& r = mHingeRest[hi];
                mHingeEnergy[hi] = 0.0;
                if (!(r.scale > 0.0)) continue;
                const auto& v = mHinges[hi].v;
                const double c = kb * r.scale;
                Vec3 s = Vec3::Zero(), sv = Vec3::Zero();
                for (int a = 0; a < 4; ++a) {
                    s += r.k[a] * vec3At(in.x, v[a]);
                    sv += r.k[a] * vec3At(in.v, v[a]);
                }
                if (mCurved) { // s − r(x): the rest s̄ carried into the current hinge frame
                    const Vec3 p[4] = {vec3At(in.x, v[0]), vec3At(in.x, v[1]), vec3At(in.x, v[2]),
                                       vec3At(in.x, v[3])};
                    s -= hingeFrame(p) * r.bent;
                }
                mHingeEnergy[hi] = 0.5 * c * s.squaredNorm();
                // f_a −= c k_a (s + β ṡ), (K v)_a += c k_a ṡ.
                const Vec3 fs = c * (s + beta * sv), fv = c * sv;
                for (int a = 0; a < 4; ++a) {
                    f.segment<3>(3 * v[a]) -= r.k[a] * fs;
                    if (kv) kv->segment<3>(3 * v[a]) += r.k[a] * fv;
                }
            }
        };
        forEachColour(mHingeBlocks, false, nh >= kParallelElements && arenaConcurrency() >= 2,
                      hinges);
        for (size_t hi = 0; hi < nh; ++hi) energy += mHingeEnergy[hi];
        // Σ over hinges of cK·Q, summed per slot at setup (mBendCoef).
        if (A)
            parallelChunks(mBendSlots.size(), 4096, [&](size_t k0, size_t k1) {
                for (size_t k = k0; k < k1; ++k)
                    A->addDiagonal(mBendSlots[k], cK * kb * mBendCoef[k]);
            });
    }
    out.elasticEnergy += energy;
}

} // namespace gale::solver
