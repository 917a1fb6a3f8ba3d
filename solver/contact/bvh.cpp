// The AABB tree: median splits (std::nth_element on the widest centre axis), leaves of up to
// four primitives, nodes stored parents first so that a refit is one reverse sweep.
#include "solver/contact/bvh.h"

#include <algorithm>

namespace gale::solver::contact {

namespace {
constexpr int kLeafSize = 4;
}

void Bvh::build(const std::vector<Box>& boxes) {
    mNodes.clear();
    clearLabels();
    mOrder.resize(boxes.size());
    for (size_t i = 0; i < boxes.size(); ++i) mOrder[i] = static_cast<int>(i);
    std::vector<Eigen::Vector3d> centres(boxes.size());
    for (size_t i = 0; i < boxes.size(); ++i) centres[i] = 0.5 * (boxes[i].lo + boxes[i].hi);
    mNodes.reserve(2 * boxes.size() / kLeafSize + 2);
    if (boxes.empty()) {
        mNodes.emplace_back();
        mLeafBoxes.clear();
        return;
    }
    buildRange(boxes, centres, 0, static_cast<int>(boxes.size()));
    mLeafBoxes.resize(boxes.size());
    for (size_t i = 0; i < boxes.size(); ++i) mLeafBoxes[i] = boxes[mOrder[i]];
}

int Bvh::buildRange(const std::vector<Box>& boxes, std::vector<Eigen::Vector3d>& centres, int begin,
                    int end) {
    const int id = static_cast<int>(mNodes.size());
    mNodes.emplace_back();
    Box box, cbox;
    for (int i = begin; i < end; ++i) {
        box.add(boxes[mOrder[i]]);
        cbox.add(centres[mOrder[i]]);
    }
    mNodes[id].box = box;
    mNodes[id].begin = begin;
    mNodes[id].end = end;
    if (end - begin <= kLeafSize) return id;
    int axis = 0;
    const Eigen::Vector3d ext = cbox.hi - cbox.lo;
    if (ext.y() > ext[axis]) axis = 1;
    if (ext.z() > ext[axis]) axis = 2;
    const int mid = begin + (end - begin) / 2;
    std::nth_element(mOrder.begin() + begin, mOrder.begin() + mid, mOrder.begin() + end,
                     [&](int a, int b) {
                         return centres[a][axis] < centres[b][axis] ||
                                (centres[a][axis] == centres[b][axis] && a < b);
                     });
    const int l = buildRange(boxes, centres, begin, mid);
    const int r = buildRange(boxes, centres, mid, end);
    mNodes[id].left = l;
    mNodes[id].right = r;
    return id;
}

void Bvh::refit(const std::vector<Box>& boxes) {
    for (size_t i = 0; i < mOrder.size(); ++i) mLeafBoxes[i] = boxes[mOrder[i]];
    refitNodes();
}

void Bvh::refitNodes() {
    for (size_t k = mNodes.size(); k-- > 0;) {
        Node& n = mNodes[k];
        Box b;
        if (n.left < 0) {
            for (int i = n.begin; i < n.end; ++i) b.add(mLeafBoxes[i]);
        } else {
            b.add(mNodes[n.left].box);
            b.add(mNodes[n.right].box);
        }
        n.box = b;
    }
}

void Bvh::setLabels(const std::vector<int>& labelOfPrimitive) {
    mLeafLabel.resize(mOrder.size());
    for (std::size_t i = 0; i < mOrder.size(); ++i)
        mLeafLabel[i] = labelOfPrimitive[static_cast<std::size_t>(mOrder[i])];
    mNodeLabel.assign(mNodes.size(), -1);
    for (std::size_t k = mNodes.size(); k-- > 0;) {
        const Node& n = mNodes[k];
        int label = -1;
        if (n.left < 0) {
            if (n.end > n.begin)
                label = labelOfPrimitive[static_cast<std::size_t>(mOrder[n.begin])];
            for (int i = n.begin + 1; i < n.end && label >= 0; ++i)
                if (labelOfPrimitive[static_cast<std::size_t>(mOrder[i])] != label) label = -1;
        } else if (mNodeLabel[n.left] == mNodeLabel[n.right]) {
            label = mNodeLabel[n.left];
        }
        mNodeLabel[k] = label;
    }
}

std::vector<Bvh::PairTask> Bvh::pairTasks(const Bvh& other, std::size_t count) const {
    std::vector<PairTask> tasks;
    if (mOrder.empty() || other.mOrder.empty()) return tasks;
    tasks.push_back({0, 0});
    // Level by level, each task replaced by its children in the order the walk pops them (the
    // reverse of their push order); pairs whose boxes do not overlap give nothing and are dropped.
    while (tasks.size() < count) {
        std::vector<PairTask> next;
        bool split = false;
        for (const PairTask& t : tasks) {
            PairTask kids[3];
            const int k = this->split(other, t, kids);
            if (k < 0) continue;
            if (k == 0) {
                next.push_back(t);
                continue;
            }
            split = true;
            for (int i = k - 1; i >= 0; --i) next.push_back(kids[i]);
        }
        tasks.swap(next);
        if (!split) break;
    }
    return tasks;
}

std::size_t Bvh::query(const Box& q, const std::function<void(int)>& fn) const {
    return queryEach(q, fn);
}

} // namespace gale::solver::contact
