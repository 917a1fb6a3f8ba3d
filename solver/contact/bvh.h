// A bounding volume hierarchy of axis-aligned boxes over a fixed set of primitives (triangles,
// edges, vertices): built once top-down by median splits along the widest axis of the box
// centres, then refitted bottom-up when the primitives move (the tree's topology kept, so a
// refit costs one pass over the nodes), and queried with a box.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <vector>

namespace gale::solver::contact {

struct Box {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY),
                    hi = Eigen::Vector3d::Constant(-INFINITY);
    void add(const Eigen::Vector3d& p) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    void add(const Box& b) {
        lo = lo.cwiseMin(b.lo);
        hi = hi.cwiseMax(b.hi);
    }
    void inflate(double r) {
        lo.array() -= r;
        hi.array() += r;
    }
    bool overlaps(const Box& b) const {
        return (lo.array() <= b.hi.array()).all() && (b.lo.array() <= hi.array()).all();
    }
    // The squared distance from p to the box (0 inside): a lower bound for any point in it.
    double distance2(const Eigen::Vector3d& p) const {
        return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
    }
};

class Bvh {
public:
    // Builds the tree over `boxes` (one per primitive, index = primitive id).
    void build(const std::vector<Box>& boxes);
    // New boxes for the same primitives (same count): every node's box recomputed bottom-up.
    void refit(const std::vector<Box>& boxes);
    // Calls fn(primitive) for every primitive whose box overlaps `q`; returns the nodes visited.
    std::size_t query(const Box& q, const std::function<void(int)>& fn) const;
    // Calls fn(a, b) for every primitive a of this tree and b of `other` whose boxes overlap, by
    // one simultaneous descent of both trees (cheaper than a query per primitive when most of
    // them have neighbours). With other == *this, each unordered pair a ≠ b comes once.
    template <class Fn>
    void overlappingPairs(const Bvh& other, Fn&& fn) const;
    // The same walk without std::function (the visitor inlined): fn(primitive) in query()'s order.
    template <class Fn>
    std::size_t queryEach(const Box& q, Fn&& fn) const {
        return traverse([&](const Box& b) { return b.overlaps(q); },
                        [&](int i, const Box& b) {
                            if (b.overlaps(q)) fn(i);
                        });
    }
    // Depth-first, in query()'s order (left subtree first), into every node whose box passes
    // enter(box), calling leaf(primitive, box) for the primitives of the leaves reached. enter
    // may tighten as the walk goes (a nearest-point search shrinking its radius). Returns the
    // nodes visited.
    template <class Enter, class Leaf>
    std::size_t traverse(Enter&& enter, Leaf&& leaf) const {
        if (mOrder.empty()) return 0;
        std::size_t visited = 0;
        int stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& n = mNodes[stack[--top]];
            ++visited;
            if (!enter(n.box)) continue;
            if (n.left < 0) {
                for (int i = n.begin; i < n.end; ++i) leaf(mOrder[i], mBoxes[mOrder[i]]);
            } else {
                stack[top++] = n.left;
                stack[top++] = n.right;
            }
        }
        return visited;
    }
    std::size_t nodeCount() const { return mNodes.size(); }
    std::size_t primitiveCount() const { return mOrder.size(); }
    const Box& rootBox() const { return mNodes.front().box; }

private:
    struct Node {
        Box box;
        int left = -1, right = -1; // children (inner node), or -1
        int begin = 0, end = 0;    // leaf: primitives mOrder[begin, end)
    };
    int buildRange(const std::vector<Box>& boxes, std::vector<Eigen::Vector3d>& centres, int begin,
                   int end);
    std::vector<Node> mNodes; // parents before children: a refit runs in reverse
    std::vector<int> mOrder;
    std::vector<Box> mBoxes; // per primitive, as last built or refitted
};

template <class Fn>
void Bvh::overlappingPairs(const Bvh& other, Fn&& fn) const {
    if (mOrder.empty() || other.mOrder.empty()) return;
    const bool self = &other == this;
    struct Task {
        int a, b;
    };
    std::vector<Task> stack;
    stack.push_back({0, 0});
    while (!stack.empty()) {
        const Task t = stack.back();
        stack.pop_back();
        const Node& na = mNodes[t.a];
        const Node& nb = other.mNodes[t.b];
        if (!na.box.overlaps(nb.box)) continue;
        const bool leafA = na.left < 0, leafB = nb.left < 0;
        if (self && t.a == t.b) {
            if (leafA) {
                for (int i = na.begin; i < na.end; ++i)
                    for (int j = i + 1; j < na.end; ++j)
                        if (mBoxes[mOrder[i]].overlaps(mBoxes[mOrder[j]])) fn(mOrder[i], mOrder[j]);
            } else {
                stack.push_back({na.left, na.left});
                stack.push_back({na.right, na.right});
                stack.push_back({na.left, na.right});
            }
            continue;
        }
        if (leafA && leafB) {
            for (int i = na.begin; i < na.end; ++i)
                for (int j = nb.begin; j < nb.end; ++j)
                    if (mBoxes[mOrder[i]].overlaps(other.mBoxes[other.mOrder[j]]))
                        fn(mOrder[i], other.mOrder[j]);
        } else if (leafB ||
                   (!leafA && (na.box.hi - na.box.lo).sum() >= (nb.box.hi - nb.box.lo).sum())) {
            stack.push_back({na.left, t.b});
            stack.push_back({na.right, t.b});
        } else {
            stack.push_back({t.a, nb.left});
            stack.push_back({t.a, nb.right});
        }
    }
}

} // namespace gale::solver::contact
