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
    // The squared distance between two boxes (0 when they overlap): a lower bound for the
    // distance between any point of one and any point of the other.
    double distance2(const Box& b) const {
        return (lo - b.hi).cwiseMax(b.lo - hi).cwiseMax(0.0).squaredNorm();
    }
};

class Bvh {
public:
    // Builds the tree over `boxes` (one per primitive, index = primitive id).
    void build(const std::vector<Box>& boxes);
    // New boxes for the same primitives (same count): every node's box recomputed bottom-up.
    void refit(const std::vector<Box>& boxes);
    // The same with primitive p's box boxOf(p), written straight in leaf order.
    template <class BoxOf>
    void refitBy(BoxOf&& boxOf) {
        for (std::size_t i = 0; i < mOrder.size(); ++i) mLeafBoxes[i] = boxOf(mOrder[i]);
        refitNodes();
    }
    // Calls fn(primitive) for every primitive whose box overlaps `q`; returns the nodes visited.
    std::size_t query(const Box& q, const std::function<void(int)>& fn) const;
    // Calls fn(a, b) for every primitive a of this tree and b of `other` whose boxes overlap, by
    // one simultaneous descent of both trees (cheaper than a query per primitive when most of
    // them have neighbours). With other == *this, each unordered pair a ≠ b comes once.
    template <class Fn>
    void overlappingPairs(const Bvh& other, Fn&& fn) const {
        if (!mOrder.empty() && !other.mOrder.empty()) overlappingPairs(other, PairTask{0, 0}, fn);
    }
    // A node pair of that descent (this tree's node a, other's node b).
    struct PairTask {
        int a, b;
    };
    // The descent split into independent parts, at least `count` of them where the trees have
    // that many overlapping node pairs: overlappingPairs(other, task, fn) over the tasks in order
    // calls fn with exactly the pairs, in exactly the order, of overlappingPairs(other, fn) (a
    // depth-first walk finishes each node pair before the one pushed below it). The parts can
    // run in parallel and their outputs be concatenated: the result then does not depend on the
    // threads.
    std::vector<PairTask> pairTasks(const Bvh& other, std::size_t count) const;
    // The descent from one node pair (a task of pairTasks).
    template <class Fn>
    void overlappingPairs(const Bvh& other, PairTask start, Fn&& fn) const;
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
                for (int i = n.begin; i < n.end; ++i) leaf(mOrder[i], mLeafBoxes[i]);
            } else {
                stack[top++] = n.left;
                stack[top++] = n.right;
            }
        }
        return visited;
    }
    // A nearest-primitive search: key(box) is a lower bound for the distance (any monotone
    // measure, e.g. squared) from the query to anything in the box, bound() the largest key
    // still of interest (the best found so far, shrinking as leaf() finds closer primitives).
    // Nodes whose key exceeds bound() are skipped; of two children the closer is walked first,
    // so the bound shrinks early. Every primitive whose leaf box keys within the bound when its
    // leaf is reached is passed to leaf(primitive, box): a search that keeps the lowest
    // (distance, index) pair finds the same result as a plain query, in fewer visits. Returns
    // the nodes visited.
    template <class Key, class Bound, class Leaf>
    std::size_t nearestFirst(Key&& key, Bound&& bound, Leaf&& leaf) const {
        if (mOrder.empty()) return 0;
        std::size_t visited = 0;
        struct Entry {
            int node;
            double key;
        };
        Entry stack[128];
        int top = 0;
        stack[top++] = {0, key(mNodes[0].box)};
        while (top > 0) {
            const Entry e = stack[--top];
            ++visited;
            if (e.key > bound()) continue;
            const Node& n = mNodes[e.node];
            if (n.left < 0) {
                for (int i = n.begin; i < n.end; ++i)
                    if (key(mLeafBoxes[i]) <= bound()) leaf(mOrder[i], mLeafBoxes[i]);
                continue;
            }
            const double kl = key(mNodes[n.left].box), kr = key(mNodes[n.right].box);
            // The farther child below the closer one on the stack (ties: the left one first).
            if (kl <= kr) {
                stack[top++] = {n.right, kr};
                stack[top++] = {n.left, kl};
            } else {
                stack[top++] = {n.left, kl};
                stack[top++] = {n.right, kr};
            }
        }
        return visited;
    }
    std::size_t nodeCount() const { return mNodes.size(); }
    std::size_t primitiveCount() const { return mOrder.size(); }
    const Box& rootBox() const { return mNodes.front().box; }
    // The tree's shape, for a caller that computes its own per-node bounds (parents before
    // children, node 0 the root): children (−1 at a leaf) and the node's primitives,
    // primitiveAt(begin) … primitiveAt(end − 1), a contiguous range for every node.
    struct NodeView {
        int left, right, begin, end;
    };
    NodeView node(int i) const {
        const Node& n = mNodes[static_cast<std::size_t>(i)];
        return {n.left, n.right, n.begin, n.end};
    }
    int primitiveAt(int i) const { return mOrder[static_cast<std::size_t>(i)]; }

    // Labels that prune the pair walk: a pair of primitives of one label ≥ 0 (the same in both
    // trees) is never reported, and a node pair whose primitives all carry that label is
    // skipped with everything below it. A caller labels primitives
    // whose pairs it has ruled out otherwise (a certified flat patch of cloth), −1 for the rest;
    // the walk's other pairs and their order are unchanged. Cleared by build() and
    // clearLabels(); query() and traverse() ignore them.
    void setLabels(const std::vector<int>& labelOfPrimitive);
    void clearLabels() {
        mNodeLabel.clear();
        mLeafLabel.clear();
    }

private:
    struct Node {
        Box box;
        int left = -1, right = -1; // children (inner node), or -1
        int begin = 0, end = 0;    // leaf: primitives mOrder[begin, end)
    };
    int buildRange(const std::vector<Box>& boxes, std::vector<Eigen::Vector3d>& centres, int begin,
                   int end);
    void refitNodes(); // every node's box from mLeafBoxes, bottom-up
    // One step of the descent from node pair t: −1 when the nodes' boxes do not overlap, 0 for a
    // pair of leaves (or a leaf with itself), else the number of child pairs written to `kids`
    // in the order they are pushed on the walk's stack (so popped in reverse).
    int split(const Bvh& other, PairTask t, PairTask kids[3]) const;
    std::vector<Node> mNodes; // parents before children: a refit runs in reverse
    std::vector<int> mOrder;
    // Per primitive as last built or refitted, in leaf order: mLeafBoxes[i] is primitive
    // mOrder[i]'s (the pair tests of a leaf read them contiguously).
    std::vector<Box> mLeafBoxes;
    std::vector<int> mNodeLabel; // per node: its primitives' common label, or −1; empty: none
    std::vector<int> mLeafLabel; // per primitive in leaf order (as mLeafBoxes); empty: none
};

inline int Bvh::split(const Bvh& other, PairTask t, PairTask kids[3]) const {
    const Node& na = mNodes[t.a];
    const Node& nb = other.mNodes[t.b];
    if (!na.box.overlaps(nb.box)) return -1;
    if (!mNodeLabel.empty() && !other.mNodeLabel.empty()) {
        const int la = mNodeLabel[static_cast<std::size_t>(t.a)];
        if (la >= 0 && la == other.mNodeLabel[static_cast<std::size_t>(t.b)]) return -1;
    }
    const bool leafA = na.left < 0, leafB = nb.left < 0;
    if (&other == this && t.a == t.b) {
        if (leafA) return 0;
        kids[0] = {na.left, na.left};
        kids[1] = {na.right, na.right};
        kids[2] = {na.left, na.right};
        return 3;
    }
    if (leafA && leafB) return 0;
    if (leafB || (!leafA && (na.box.hi - na.box.lo).sum() >= (nb.box.hi - nb.box.lo).sum())) {
        kids[0] = {na.left, t.b};
        kids[1] = {na.right, t.b};
    } else {
        kids[0] = {t.a, nb.left};
        kids[1] = {t.a, nb.right};
    }
    return 2;
}

template <class Fn>
void Bvh::overlappingPairs(const Bvh& other, PairTask start, Fn&& fn) const {
    const bool self = &other == this;
    // Each step pops one pair and pushes ≤ 3, one level deeper in either tree: ≤ 2 per level of
    // the ≤ 60 levels of two median-split trees over < 2³¹ primitives.
    PairTask stack[256];
    int top = 0;
    stack[top++] = start;
    while (top > 0) {
        const PairTask t = stack[--top];
        PairTask kids[3];
        const int k = split(other, t, kids);
        if (k > 0) {
            for (int i = 0; i < k; ++i) stack[top++] = kids[i];
            continue;
        }
        if (k < 0) continue;
        const Node& na = mNodes[t.a];
        const Node& nb = other.mNodes[t.b];
        // Two primitives of one label ≥ 0 are skipped here too (leaves with mixed labels).
        const bool labels = !mLeafLabel.empty() && !other.mLeafLabel.empty();
        const auto sameLabel = [&](int i, int j) {
            return labels && mLeafLabel[i] >= 0 && mLeafLabel[i] == other.mLeafLabel[j];
        };
        if (self && t.a == t.b) {
            for (int i = na.begin; i < na.end; ++i)
                for (int j = i + 1; j < na.end; ++j)
                    if (mLeafBoxes[i].overlaps(mLeafBoxes[j]) && !sameLabel(i, j))
                        fn(mOrder[i], mOrder[j]);
            continue;
        }
        for (int i = na.begin; i < na.end; ++i) {
            const Box& bi = mLeafBoxes[i];
            for (int j = nb.begin; j < nb.end; ++j)
                if (bi.overlaps(other.mLeafBoxes[j]) && !sameLabel(i, j))
                    fn(mOrder[i], other.mOrder[j]);
        }
    }
}

} // namespace gale::solver::contact
