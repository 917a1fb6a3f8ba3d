// Hair strands: springs (EA/L), bending (EI/L̄ |Δt − R Δt̄|²/2, straight or curled rest), Rayleigh damping and
// cross-flow drag (Wilson et al. 2014 use the normal/tangential split for hair, as Houdini's
// dragnormal/dragtangent and Maya's tangential drag do). The wind is sampled at the vertices;
// a segment feels the mean of its ends and moves with the mean of their velocities, so its
// damping matrix D contributes D/4 to each of its four vertex blocks.
#include "solver/bodies/hair.h"

#include "io/pointset.h"

#include <cmath>

namespace gale::solver {

Strands makeStrandGrid(const Vec3& origin, double width, double depth, int nu, int nv, double length,
                       int segments, const Vec3& axisU, const Vec3& axisV, const Vec3& dir) {
    Strands s;
    s.offsets = {0};
    segments = std::max(segments, 1);
    const Vec3 d = dir.normalized();
    for (int j = 0; j < std::max(nv, 1); ++j)
        for (int i = 0; i < std::max(nu, 1); ++i) {
            const double fu = nu > 1 ? static_cast<double>(i) / (nu - 1) - 0.5 : 0.0;
            const double fv = nv > 1 ? static_cast<double>(j) / (nv - 1) - 0.5 : 0.0;
            const Vec3 root = origin + fu * width * axisU + fv * depth * axisV;
            for (int k = 0; k <= segments; ++k) {
                const Vec3 p = root + (length * k / segments) * d;
                s.positions.insert(s.positions.end(), {p.x(), p.y(), p.z()});
            }
            s.offsets.push_back(static_cast<int>(s.positions.size() / 3));
        }
    return s;
}

bool loadStrands(const std::string& path, Strands& out, std::string& error) {
    io::PointSet ps;
    if (io::IoError e = io::readPoints(path, ps)) {
        error = e.brief(); // the caller's diagnostic says "error:" once
        return false;
    }
    const int ix = ps.find("x"), iy = ps.find("y"), iz = ps.find("z"), is = ps.find("strand");
    if (ix < 0 || iy < 0 || iz < 0 || is < 0) {
        error = path + ": strands need x, y, z and an integer 'strand' vertex property";
        return false;
    }
    out = Strands{};
    const size_t n = ps.size();
    std::vector<size_t> keep;
    size_t i = 0;
    while (i < n) {
        size_t j = i + 1;
        while (j < n && ps.columns[is][j] == ps.columns[is][i]) ++j;
        if (j - i >= 2) {
            for (size_t k = i; k < j; ++k) {
                out.positions.insert(out.positions.end(), {ps.columns[ix][k], ps.columns[iy][k], ps.columns[iz][k]});
                keep.push_back(k);
            }
            out.offsets.push_back(static_cast<int>(out.positions.size() / 3));
        }
        i = j;
    }
    if (out.strandCount() == 0) {
        error = path + ": no strand has two or more vertices";
        return false;
    }
    for (size_t c = 0; c < ps.names.size(); ++c) {
        const std::string& name = ps.names[c];
        if (name == "x" || name == "y" || name == "z" || name == "strand") continue;
        std::vector<double> col;
        col.reserve(keep.size());
        for (size_t k : keep) col.push_back(ps.columns[c][k]);
        out.attributes[name] = std::move(col);
    }
    return true;
}

namespace {
VecX flatten(const std::vector<double>& p) { return Eigen::Map<const VecX>(p.data(), p.size()); }
} // namespace

Hair::Hair(std::string name, Strands strands, HairMaterial material)
    : Body(std::move(name), flatten(strands.positions)), mStrands(std::move(strands)), mMat(std::move(material)) {
    mOptions.linearSolver = LinearSolverKind::Direct; // a chain's system is banded
    const double lambda = mMat.density * 3.14159265358979323846 * mMat.radius * mMat.radius; // kg/m
    const double* x = mStrands.positions.data();
    std::vector<std::array<int, 2>> edges;
    for (size_t s = 0; s < mStrands.strandCount(); ++s) {
        const int b = mStrands.offsets[s], e = mStrands.offsets[s + 1];
        for (int i = b; i + 1 < e; ++i) {
            const double L = (vec3At(x, i + 1) - vec3At(x, i)).norm();
            mSegments.push_back({i, i + 1, L});
            edges.push_back({i, i + 1});
            if (std::isfinite(L)) {
                mMass[i] += 0.5 * lambda * L;
                mMass[i + 1] += 0.5 * lambda * L;
            }
        }
        for (int i = b + 1; i + 1 < e; ++i) {
            const double l0 = (vec3At(x, i) - vec3At(x, i - 1)).norm();
            const double l1 = (vec3At(x, i + 1) - vec3At(x, i)).norm();
            if (!(l0 > 0.0) || !(l1 > 0.0)) continue;
            Bend bd;
            bd.v[0] = i - 1;
            bd.v[1] = i;
            bd.v[2] = i + 1;
            bd.w = strandBendWeights(l0, l1);
            bd.invLength = 2.0 / (l0 + l1);
            if (mMat.curledRest) {
                for (int a = 0; a < 3; ++a) bd.restD += bd.w[a] * vec3At(x, bd.v[a]);
                bd.restTangent = (vec3At(x, i) - vec3At(x, i - 1)) / l0;
            }
            mBends.push_back(bd);
        }
    }
    auto segMean = [&](const std::vector<double>& map, std::vector<double>& out) {
        out.clear();
        if (map.size() != vertexCount()) return;
        for (const Segment& sg : mSegments) out.push_back(0.5 * (map[sg.a] + map[sg.b]));
    };
    segMean(mMat.dragNormal.map, mSegCn);
    segMean(mMat.dragTangent.map, mSegCt);
    finishSetup(edges);
    mSegSlots.resize(mSegments.size());
    for (size_t k = 0; k < mSegments.size(); ++k) {
        const int v[2] = {mSegments[k].a, mSegments[k].b};
        for (int a = 0; a < 2; ++a)
            for (int c = 0; c < 2; ++c) mSegSlots[k][2 * a + c] = matrix().slot(v[a], v[c]);
    }
    mBendSlots.resize(mBends.size());
    for (size_t k = 0; k < mBends.size(); ++k)
        for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c) mBendSlots[k][3 * a + c] = matrix().slot(mBends[k].v[a], mBends[k].v[c]);
    if (mMat.rootPinned) {
        PinSet roots;
        for (size_t s = 0; s < mStrands.strandCount(); ++s) roots.vertices.push_back(mStrands.offsets[s]);
        addPins(roots);
    }
}

void Hair::couplings(std::vector<std::pair<int, int>>& pairs) const {
    for (const Segment& s : mSegments) pairs.push_back({s.a, s.b});
    for (const Bend& b : mBends) pairs.push_back({b.v[0], b.v[2]});
}

void Hair::addForces(const ForceInput& in, ForceOutput& out) {
    const double t = in.t, h = in.h;
    const double ea = mMat.stretch.scalarAt(t), ei = mMat.bend.scalarAt(t), beta = mMat.damping.scalarAt(t);
    const double cK = h * h + h * beta;
    VecX& f = *out.f;
    VecX* kv = out.kv;
    BlockMatrix* A = out.A;

    SpringElastic se;
    for (size_t k = 0; k < mSegments.size(); ++k) {
        const Segment& s = mSegments[k];
        springForces(vec3At(in.x, s.a), vec3At(in.x, s.b), s.rest, ea, se);
        out.elasticEnergy += se.energy;
        const Vec3 kvb = se.K * (vec3At(in.v, s.b) - vec3At(in.v, s.a)); // (K v) at b; −that at a
        f.segment<3>(3 * s.a) += se.f0 + beta * kvb;
        f.segment<3>(3 * s.b) += -se.f0 - beta * kvb;
        if (kv) {
            kv->segment<3>(3 * s.a) -= kvb;
            kv->segment<3>(3 * s.b) += kvb;
        }
        if (A) {
            A->addBlock(mSegSlots[k][0], se.K, cK);
            A->addBlock(mSegSlots[k][1], se.K, -cK);
            A->addBlock(mSegSlots[k][2], se.K, -cK);
            A->addBlock(mSegSlots[k][3], se.K, cK);
        }
    }

    if (ei != 0.0)
        for (size_t k = 0; k < mBends.size(); ++k) {
            const Bend& b = mBends[k];
            const double c = ei * b.invLength;
            Vec3 d = Vec3::Zero(), dv = Vec3::Zero();
            for (int a = 0; a < 3; ++a) {
                d += b.w[a] * vec3At(in.x, b.v[a]);
                dv += b.w[a] * vec3At(in.v, b.v[a]);
            }
            if (mMat.curledRest)
                d -= strandBendTarget(b.restD, b.restTangent, vec3At(in.x, b.v[1]) - vec3At(in.x, b.v[0]));
            out.elasticEnergy += 0.5 * c * d.squaredNorm();
            for (int a = 0; a < 3; ++a) {
                f.segment<3>(3 * b.v[a]) -= c * b.w[a] * (d + beta * dv);
                if (kv) kv->segment<3>(3 * b.v[a]) += c * b.w[a] * dv;
            }
            if (A)
                for (int a = 0; a < 3; ++a)
                    for (int cc = 0; cc < 3; ++cc) A->addDiagonal(mBendSlots[k][3 * a + cc], cK * c * b.w[a] * b.w[cc]);
        }

    if (!in.wind) return;
    const double cn0 = mMat.dragNormal.at(t), ct0 = mMat.dragTangent.at(t);
    if (cn0 == 0.0 && ct0 == 0.0) return;
    const double d = 2.0 * mMat.radius;
    for (size_t k = 0; k < mSegments.size(); ++k) {
        const Segment& s = mSegments[k];
        const Vec3 e = vec3At(in.x, s.b) - vec3At(in.x, s.a);
        const double len = e.norm();
        if (!(len > 0.0)) continue;
        const Vec3 wind = 0.5 * (vec3At(in.wind, s.a) + vec3At(in.wind, s.b));
        const Vec3 u = 0.5 * (vec3At(in.v, s.a) + vec3At(in.v, s.b));
        const double cn = std::max(0.0, mSegCn.empty() ? cn0 : cn0 * mSegCn[k]);
        const double ct = std::max(0.0, mSegCt.empty() ? ct0 : ct0 * mSegCt[k]);
        // Drag area uses the current length (the fibre's surface stretches with it).
        const AeroResult r = aeroSegment(wind - u, e / len, len, d, in.airDensity, cn, ct);
        f.segment<3>(3 * s.a) += 0.5 * r.force;
        f.segment<3>(3 * s.b) += 0.5 * r.force;
        if (A && in.aeroJacobian != AeroJacobian::None)
            for (int q = 0; q < 4; ++q) A->addBlock(mSegSlots[k][q], r.damping, h / 4.0);
    }
}

} // namespace gale::solver
