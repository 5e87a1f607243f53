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

struct Builder {
  const std::vector<Vec3d>& lo;
  const std::vector<Vec3d>& hi;
  double pad;
  std::vector<Vec3d> centroid;
  std::vector<std::uint32_t>& order;
  std::vector<BvhNode>& nodes;

  void set_box(BvhNode& n, const Box& b) const {
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
        const double cost = left.area() * lcnt + right_area[b + 1] * right_count[b + 1];
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = a;
          best_bin = b;
        }
      }
    }
    // A leaf when splitting costs more than intersecting all (traversal
    // cost 1 per node, 1 per triangle) and the leaf is small enough.
    if (n <= std::uint32_t(Bvh::kMaxLeaf) && (best_axis < 0 || best_cost / box.area() + 1 >= double(n)))
      return make_leaf();

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

}  // namespace

Bvh Bvh::build(const std::vector<Vec3d>& lo, const std::vector<Vec3d>& hi, double pad) {
  Bvh bvh;
  const std::size_t n = lo.size();
  bvh.order.resize(n);
  std::iota(bvh.order.begin(), bvh.order.end(), 0u);
  if (n == 0) return bvh;
  bvh.nodes.reserve(2 * n / Bvh::kMaxLeaf + 1);
  Builder b{lo, hi, pad, {}, bvh.order, bvh.nodes};
  b.centroid.resize(n);
  for (std::size_t i = 0; i < n; ++i) b.centroid[i] = (lo[i] + hi[i]) * 0.5;
  b.build(0, std::uint32_t(n), 0);
  return bvh;
}

}  // namespace ra
