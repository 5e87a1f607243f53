// Builds renderer/accel/bvh.h's 4-wide BVH: a binned SAH binary tree (Wald
// 2007) collapsed to 4 children per node (largest box opened first).
#include "bvh.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace ra {
namespace {

// Past this depth splits are halvings: the tree is never deeper than
// kMaxSahDepth + 32, within the traversal stack (Bvh::kMaxDepth).
constexpr int kMaxSahDepth = 64;

struct Box {
  Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  void grow(const Vec3d& l, const Vec3d& h) {
    lo = vmin(lo, l);
    hi = vmax(hi, h);
  }
  double area() const {
    if (!(lo.x <= hi.x)) return 0;
    const Vec3d e = hi - lo;
    return 2 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

// A binary node of the first pass.
struct BinNode {
  float lo[3], hi[3];
  std::uint32_t index;  // leaf: first slot; interior: the right child
  std::uint16_t count;  // leaf: number of triangles (> 0); interior: 0
  std::uint16_t axis;
};

struct Builder {
  const std::vector<Vec3d>& lo;
  const std::vector<Vec3d>& hi;
  double pad;
  std::vector<Vec3d> centroid;
  std::vector<std::uint32_t>& order;
  std::vector<BinNode>& nodes;

  void set_box(BinNode& n, const Box& b) const {
    for (int a = 0; a < 3; ++a) {
      n.lo[a] = std::nextafter(float(b.lo[a] - pad), -INFINITY);
      n.hi[a] = std::nextafter(float(b.hi[a] + pad), INFINITY);
    }
  }

  // Builds the subtree over order[begin, end); returns its node index.
  std::uint32_t build(std::uint32_t begin, std::uint32_t end, int depth) {
    const std::uint32_t me = std::uint32_t(nodes.size());
    nodes.push_back({});
    Box box, cbox;
    for (std::uint32_t i = begin; i < end; ++i) {
      const auto t = order[i];
      box.grow(lo[t], hi[t]);
      cbox.grow(centroid[t], centroid[t]);
    }
    set_box(nodes[me], box);
    const std::uint32_t n = end - begin;
    auto make_leaf = [&] {
      nodes[me].index = begin;
      nodes[me].count = std::uint16_t(n);
      return me;
    };
    if (n <= 1) return make_leaf();

    // Binned SAH over the axis of the widest centroid spread... and the
    // others: the best split of all three axes.
    int best_axis = -1, best_bin = -1;
    double best_cost = INFINITY;
    for (int a = 0; a < 3; ++a) {
      const double extent = cbox.hi[a] - cbox.lo[a];
      if (!(extent > 0)) continue;
      Box bins[Bvh::kBins];
      std::uint32_t counts[Bvh::kBins] = {};
      const double k = Bvh::kBins / extent;
      for (std::uint32_t i = begin; i < end; ++i) {
        const auto t = order[i];
        const int b = std::min(Bvh::kBins - 1, int((centroid[t][a] - cbox.lo[a]) * k));
        bins[b].grow(lo[t], hi[t]);
        ++counts[b];
      }
      double right_area[Bvh::kBins];
      std::uint32_t right_count[Bvh::kBins];
      Box acc;
      std::uint32_t cnt = 0;
      for (int b = Bvh::kBins - 1; b > 0; --b) {
        acc.grow(bins[b].lo, bins[b].hi);
        cnt += counts[b];
        right_area[b] = acc.area();
        right_count[b] = cnt;
      }
      Box left;
      std::uint32_t lcnt = 0;
      for (int b = 0; b < Bvh::kBins - 1; ++b) {
        left.grow(bins[b].lo, bins[b].hi);
        lcnt += counts[b];
        if (lcnt == 0 || right_count[b + 1] == 0) continue;
        // Leaves are tested 4 triangles at a time: cost in blocks of 4.
        const double cost = left.area() * ((lcnt + 3) / 4) + right_area[b + 1] * ((right_count[b + 1] + 3) / 4);
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = a;
          best_bin = b;
        }
      }
    }
    // Up to 4 triangles cost one leaf test whatever their number: a leaf.
    if (n <= std::uint32_t(Bvh::kMaxLeaf)) return make_leaf();

    std::uint32_t mid;
    if (best_axis < 0 || depth >= kMaxSahDepth) {
      // All centroids coincide, or a degenerate SAH chain got deep: halve
      // the range, which bounds the remaining depth by log2(n).
      mid = begin + n / 2;
      best_axis = 0;
    } else {
      const double extent = cbox.hi[best_axis] - cbox.lo[best_axis];
      const double k = Bvh::kBins / extent;
      auto it = std::partition(order.begin() + begin, order.begin() + end, [&](std::uint32_t t) {
        return std::min(Bvh::kBins - 1, int((centroid[t][best_axis] - cbox.lo[best_axis]) * k)) <= best_bin;
      });
      mid = std::uint32_t(it - order.begin());
      if (mid == begin || mid == end) mid = begin + n / 2;
    }
    build(begin, mid, depth + 1);
    const std::uint32_t right = build(mid, end, depth + 1);
    nodes[me].index = right;
    nodes[me].count = 0;
    nodes[me].axis = std::uint16_t(best_axis);
    return me;
  }
};

// Surface area of a binary node's box (the collapse opens the largest).
double node_area(const BinNode& n) {
  const double ex = double(n.hi[0]) - n.lo[0], ey = double(n.hi[1]) - n.lo[1], ez = double(n.hi[2]) - n.lo[2];
  return ex * ey + ey * ez + ez * ex;
}

struct Collapser {
  const std::vector<BinNode>& bin;
  const std::vector<std::uint32_t>& bin_order;
  Bvh& out;

  // A leaf's triangles go to the next 4 slots (unused ones hold kNoTriangle).
  std::uint32_t emit_leaf(const BinNode& b) {
    const std::uint32_t k = std::uint32_t(out.order.size() / 4);
    for (int i = 0; i < 4; ++i) out.order.push_back(i < b.count ? bin_order[b.index + i] : Bvh::kNoTriangle);
    return Bvh::make_leaf(k, b.count);
  }

  // Emits the 4-wide node for binary node `bi` (interior, or a root leaf).
  std::uint32_t emit(std::uint32_t bi) {
    std::uint32_t kids[4];
    int n = 0;
    if (bin[bi].count > 0) {
      kids[n++] = bi;
    } else {
      kids[n++] = bi + 1;
      kids[n++] = bin[bi].index;
      while (n < 4) {
        int best = -1;
        double best_area = -1;
        for (int i = 0; i < n; ++i)
          if (bin[kids[i]].count == 0 && node_area(bin[kids[i]]) > best_area) {
            best_area = node_area(bin[kids[i]]);
            best = i;
          }
        if (best < 0) break;
        const std::uint32_t open = kids[best];
        kids[best] = open + 1;
        kids[n++] = bin[open].index;
      }
    }
    const std::uint32_t me = std::uint32_t(out.nodes.size());
    out.nodes.emplace_back();
    std::uint32_t child[4];
    for (int i = 0; i < 4; ++i) {
      if (i >= n) {
        child[i] = Bvh::kEmpty;
        continue;
      }
      const BinNode& b = bin[kids[i]];
      child[i] = b.count > 0 ? emit_leaf(b) : emit(kids[i]);
    }
    BvhNode4& node = out.nodes[me];
    for (int i = 0; i < 4; ++i) {
      node.child[i] = child[i];
      for (int a = 0; a < 3; ++a) {
        node.lo[a][i] = i < n ? bin[kids[i]].lo[a] : INFINITY;
        node.hi[a][i] = i < n ? bin[kids[i]].hi[a] : -INFINITY;
      }
    }
    return me;
  }
};

}  // namespace

Bvh Bvh::build(const std::vector<Vec3d>& lo, const std::vector<Vec3d>& hi, double pad, int threads) {
  Bvh bvh;
  const std::size_t n = lo.size();
  if (n == 0) return bvh;
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::vector<BinNode> bin;
  bin.reserve(2 * n / Bvh::kMaxLeaf + 1);
  Builder b{lo, hi, pad, {}, order, bin};
  b.centroid.resize(n);
  for (std::size_t i = 0; i < n; ++i) b.centroid[i] = (lo[i] + hi[i]) * 0.5;
  b.build(0, std::uint32_t(n), 0);
  bvh.nodes.reserve(bin.size() / 3 + 1);
  bvh.order.reserve(4 * n);
  Collapser{bin, order, bvh}.emit(0);
  return bvh;
}

}  // namespace ra
