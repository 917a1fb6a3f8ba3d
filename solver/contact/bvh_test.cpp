// The AABB tree: queries return exactly the primitives whose boxes overlap (against brute
// force), before and after a refit to moved boxes, and a query visits far fewer nodes than a
// scan when the query box is small.
#include "solver/contact/bvh.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <random>

using namespace gale::solver::contact;

namespace {
// n boxes with corners at uniform points of the unit cube and edges up to `size`.
std::vector<Box> randomBoxes(std::mt19937& rng, int n, double size) {
    std::uniform_real_distribution<double> U(0.0, 1.0);
    std::vector<Box> out(n);
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d c(U(rng), U(rng), U(rng));
        out[i].add(c);
        out[i].add(c + size * Eigen::Vector3d(U(rng), U(rng), U(rng)));
    }
    return out;
}
} // namespace

TEST_CASE("bvh: queries match brute force, also after a refit", "[contact][bvh]") {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const int n = 5000;
    std::vector<Box> boxes(n);
    auto place = [&](double shift) {
        for (int i = 0; i < n; ++i) {
            Box b;
            const Eigen::Vector3d c(U(rng) + shift, U(rng), U(rng));
            b.add(c);
            b.add(c + Eigen::Vector3d(0.01 * U(rng), 0.01 * U(rng), 0.01 * U(rng)));
            boxes[i] = b;
        }
    };
    place(0.0);
    Bvh bvh;
    bvh.build(boxes);
    CHECK(bvh.primitiveCount() == static_cast<size_t>(n));
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1) {
            // Every primitive moves (coherently, as a body's triangles do): same tree, new boxes.
            for (Box& b : boxes) {
                const Eigen::Vector3d d(0.3, 0.02 * U(rng), 0.0);
                b.lo += d;
                b.hi += d + Eigen::Vector3d::Constant(0.002 * U(rng));
            }
            bvh.refit(boxes);
        }
        size_t visitedSum = 0;
        for (int q = 0; q < 200; ++q) {
            Box query;
            const Eigen::Vector3d c(U(rng) + 0.3 * pass, U(rng), U(rng));
            query.add(c);
            query.inflate(0.02);
            std::vector<int> got, want;
            visitedSum += bvh.query(query, [&](int i) { got.push_back(i); });
            for (int i = 0; i < n; ++i)
                if (boxes[i].overlaps(query)) want.push_back(i);
            std::sort(got.begin(), got.end());
            REQUIRE(got == want);
        }
        CHECK(visitedSum / 200 < static_cast<size_t>(n) / 20); // a small query visits few nodes
        CHECK(bvh.rootBox().lo.x() >= 0.3 * pass - 1e-12);
    }
}

TEST_CASE("bvh: overlapping pairs of two trees and of one tree match brute force", "[contact][bvh]") {
    std::mt19937 rng(11);
    auto boxes = [&](int n, double size) { return randomBoxes(rng, n, size); };
    const std::vector<Box> a = boxes(700, 0.05), b = boxes(900, 0.08);
    Bvh ta, tb;
    ta.build(a);
    tb.build(b);
    std::vector<std::pair<int, int>> got, want;
    ta.overlappingPairs(tb, [&](int i, int j) { got.emplace_back(i, j); });
    for (int i = 0; i < 700; ++i)
        for (int j = 0; j < 900; ++j)
            if (a[i].overlaps(b[j])) want.emplace_back(i, j);
    std::sort(got.begin(), got.end());
    CHECK(got == want);
    CHECK(!want.empty());
    // One tree against itself: every unordered pair i ≠ j once.
    got.clear();
    want.clear();
    tb.overlappingPairs(tb, [&](int i, int j) { got.emplace_back(std::min(i, j), std::max(i, j)); });
    for (int i = 0; i < 900; ++i)
        for (int j = i + 1; j < 900; ++j)
            if (b[i].overlaps(b[j])) want.emplace_back(i, j);
    std::sort(got.begin(), got.end());
    CHECK(std::adjacent_find(got.begin(), got.end()) == got.end());
    CHECK(got == want);
}

TEST_CASE("bvh: queryEach visits query's primitives in its order; a pruned walk finds the nearest",
          "[contact][bvh]") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    std::vector<Box> boxes(3000);
    for (Box& b : boxes) {
        const Eigen::Vector3d c(U(rng), U(rng), U(rng));
        b.add(c);
        b.add(c + Eigen::Vector3d(0.02 * U(rng), 0.02 * U(rng), 0.02 * U(rng)));
    }
    Bvh bvh;
    bvh.build(boxes);
    for (int q = 0; q < 100; ++q) {
        const Eigen::Vector3d p(U(rng), U(rng), U(rng));
        Box query;
        query.add(p);
        query.inflate(0.05);
        std::vector<int> a, b;
        const size_t va = bvh.query(query, [&](int i) { a.push_back(i); });
        const size_t vb = bvh.queryEach(query, [&](int i) { b.push_back(i); });
        REQUIRE(a == b); // same primitives, same order
        CHECK(va == vb);
        // The nearest box to p (distance 0 inside), by brute force and by a walk that skips
        // every node farther than the best so far.
        double want = INFINITY;
        for (const Box& x : boxes) want = std::min(want, x.distance2(p));
        double best = INFINITY;
        size_t leaves = 0;
        bvh.traverse([&](const Box& n) { return n.distance2(p) <= best; },
                     [&](int, const Box& x) {
                         ++leaves;
                         best = std::min(best, x.distance2(p));
                     });
        CHECK(best == want);
        CHECK(leaves < boxes.size() / 10); // the pruning skips most of the tree
    }
    Box unit;
    unit.add(Eigen::Vector3d(0, 0, 0));
    unit.add(Eigen::Vector3d(1, 1, 1));
    CHECK(unit.distance2(Eigen::Vector3d(0.5, 0.5, 0.5)) == 0.0);
    CHECK(unit.distance2(Eigen::Vector3d(2, 0.5, -1)) == Approx(2.0)); // 1² + 1²
}

TEST_CASE("bvh: the pair walk split into tasks gives the whole walk's pairs in its order",
          "[contact][bvh]") {
    // Concatenating the tasks' pairs must reproduce overlappingPairs exactly (the self-collision
    // broad phase runs the tasks in parallel and relies on the order), for two trees and for one
    // tree against itself, at several split counts, also after a refit.
    std::mt19937 rng(5);
    auto boxes = [&](int n, double size) { return randomBoxes(rng, n, size); };
    std::vector<Box> a = boxes(1200, 0.05), b = boxes(500, 0.08);
    Bvh ta, tb;
    ta.build(a);
    tb.build(b);
    for (int round = 0; round < 2; ++round) {
        for (const Bvh* other : {&tb, &ta}) {
            std::vector<std::pair<int, int>> whole;
            ta.overlappingPairs(*other, [&](int i, int j) { whole.emplace_back(i, j); });
            REQUIRE(whole.size() > 20);
            for (size_t count : {1, 2, 7, 64, 1000}) {
                const auto tasks = ta.pairTasks(*other, count);
                CHECK(tasks.size() >= std::min<size_t>(count, 8)); // these trees split that far
                std::vector<std::pair<int, int>> split;
                for (const auto& t : tasks)
                    ta.overlappingPairs(*other, t, [&](int i, int j) { split.emplace_back(i, j); });
                CHECK(split == whole);
            }
        }
        // Moved boxes, the same topology.
        a = boxes(1200, 0.06);
        ta.refit(a);
    }
    Bvh empty;
    empty.build({});
    CHECK(empty.pairTasks(ta, 8).empty());
}

TEST_CASE("bvh: the nearest-first walk finds the lowest (distance, index) of brute force",
          "[contact][bvh]") {
    // Points (degenerate boxes, many at equal distances from the grid queries below) and small
    // boxes; the search keeps the lowest (distance², primitive) pair as closest() does.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    for (double size : {0.0, 0.01}) {
        std::vector<Box> boxes(4000);
        for (size_t i = 0; i < boxes.size(); ++i) {
            // Half on a coarse lattice (ties), half uniform.
            const Eigen::Vector3d c =
                i % 2 ? Eigen::Vector3d(U(rng), U(rng), U(rng))
                      : Eigen::Vector3d(std::floor(10 * U(rng)) / 10, std::floor(10 * U(rng)) / 10,
                                        std::floor(10 * U(rng)) / 10);
            boxes[i].add(c);
            boxes[i].add(c + size * Eigen::Vector3d(U(rng), U(rng), U(rng)));
        }
        Bvh bvh;
        bvh.build(boxes);
        size_t nearestVisits = 0, plainVisits = 0;
        for (int q = 0; q < 200; ++q) {
            const Eigen::Vector3d p =
                q % 2 ? Eigen::Vector3d(U(rng), U(rng), U(rng))
                      : Eigen::Vector3d(0.05 + std::floor(10 * U(rng)) / 10,
                                        std::floor(10 * U(rng)) / 10, std::floor(10 * U(rng)) / 10);
            const double radius2 = 0.2 * 0.2;
            double want = radius2;
            int wantIndex = -1;
            for (int i = 0; i < static_cast<int>(boxes.size()); ++i) {
                const double d = boxes[i].distance2(p);
                if (d < want || (d == want && wantIndex >= 0 && i < wantIndex)) {
                    want = d;
                    wantIndex = i;
                }
            }
            double best = radius2;
            int bestIndex = -1;
            nearestVisits += bvh.nearestFirst(
                [&](const Box& b) { return b.distance2(p); }, [&] { return best; },
                [&](int i, const Box& b) {
                    const double d = b.distance2(p);
                    if (d < best || (d == best && bestIndex >= 0 && i < bestIndex)) {
                        best = d;
                        bestIndex = i;
                    }
                });
            CHECK(bestIndex == wantIndex);
            CHECK(best == want);
            // The same search as a plain walk in query order, pruned by the best so far.
            double plainBest = radius2;
            plainVisits += bvh.traverse(
                [&](const Box& b) { return b.distance2(p) <= plainBest; },
                [&](int, const Box& b) { plainBest = std::min(plainBest, b.distance2(p)); });
            CHECK(plainBest == want);
        }
        INFO("box size " << size << ": nodes visited nearest-first " << nearestVisits
                         << ", in query order " << plainVisits);
        CHECK(nearestVisits < plainVisits); // the closer child first shrinks the bound earlier
    }
    Box a, b;
    a.add(Eigen::Vector3d(0, 0, 0));
    a.add(Eigen::Vector3d(1, 1, 1));
    b.add(Eigen::Vector3d(2, 0.5, 3));
    b.add(Eigen::Vector3d(4, 0.7, 5));
    CHECK(a.distance2(b) == Approx(1.0 + 4.0)); // gaps 1 (x) and 2 (z)
    CHECK(b.distance2(a) == a.distance2(b));
    b.add(Eigen::Vector3d(0.5, 0.5, 0.5));
    CHECK(a.distance2(b) == 0.0); // overlapping
}

TEST_CASE("bvh: labels prune exactly the pairs of one label, the rest in the walk's order",
          "[contact][bvh]") {
    // Boxes along a strip, labelled in runs (−1 between): the labelled walk gives the plain
    // walk's pairs with those of two equal labels ≥ 0 filtered out, in the same order; pairs of
    // −1 or of different labels stay.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const int n = 3000;
    std::vector<Box> boxes(n);
    std::vector<int> label(n);
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d c(i / double(n), 0.02 * U(rng), 0.02 * U(rng));
        boxes[i].add(c);
        boxes[i].add(c + Eigen::Vector3d(0.003 * U(rng), 0.01, 0.01));
        label[i] = (i / 200) % 3 == 2 ? -1 : i / 200;
    }
    Bvh tree, other;
    tree.build(boxes);
    other.build(randomBoxes(rng, 800, 0.02));
    std::vector<std::pair<int, int>> whole, pruned;
    tree.overlappingPairs(tree, [&](int i, int j) { whole.emplace_back(i, j); });
    tree.setLabels(label);
    tree.overlappingPairs(tree, [&](int i, int j) { pruned.emplace_back(i, j); });
    std::vector<std::pair<int, int>> want;
    for (const auto& [i, j] : whole)
        if (!(label[i] >= 0 && label[i] == label[j])) want.push_back({i, j});
    REQUIRE(want.size() < whole.size() / 2); // the labels do cover most pairs
    REQUIRE(want.size() > 100);
    CHECK(pruned.size() == want.size());
    CHECK(pruned == want);
    // The tasks of a labelled walk give its pairs too.
    std::vector<std::pair<int, int>> split;
    for (const auto& t : tree.pairTasks(tree, 16))
        tree.overlappingPairs(tree, t, [&](int i, int j) { split.emplace_back(i, j); });
    CHECK(split == want);
    // Against an unlabelled tree nothing is pruned; clearLabels and build drop the labels.
    std::vector<std::pair<int, int>> mixed, plain;
    tree.overlappingPairs(other, [&](int i, int j) { mixed.emplace_back(i, j); });
    tree.clearLabels();
    tree.overlappingPairs(other, [&](int i, int j) { plain.emplace_back(i, j); });
    CHECK(mixed == plain);
    std::vector<std::pair<int, int>> again;
    tree.setLabels(label);
    tree.build(boxes);
    tree.overlappingPairs(tree, [&](int i, int j) { again.emplace_back(i, j); });
    CHECK(again == whole);
}
