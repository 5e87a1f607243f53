// Builds renderer/accel/bvh.h's 8-wide BVH: a binned SAH binary tree (Wald
// 2007) collapsed to 8 children per node (largest box opened first).
#include "bvh.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <thread>

namespace ra {
namespace {

// Past this depth splits are halvings: the tree is never deeper than
// kMaxSahDepth + 32, within the traversal stack (Bvh::kMaxDepth).
constexpr int kMaxSahDepth = 64;
// Subtrees smaller than this are built on the thread that split them.
constexpr std::uint32_t kMinParallel = 4096;

typedef float v4f __attribute__((vector_size(16)));
typedef int v4i __attribute__((vector_size(16)));

// A triangle's box in float, rounded outward from double; lane 3 of lo
// holds the triangle index (its bits), lane 3 of hi is unused. 32 bytes, so
// binning and partitioning stream through memory.
struct PrimRef {
  v4f lo, hi;
  std::uint32_t id() const {
    std::uint32_t i;
    __builtin_memcpy(&i, reinterpret_cast<const char*>(&lo) + 12, 4);
    return i;
  }
};

// No default initialisation (bins are cleared only as far as used):
// start from Box::empty().
struct Box {
  v4f lo, hi;
  static Box empty() { return {v4f{} + INFINITY, v4f{} - INFINITY}; }
  void grow(v4f l, v4f h) {
    lo = l < lo ? l : lo;
    hi = h > hi ? h : hi;
  }
  double area() const {
    if (!(lo[0] <= hi[0])) return 0;
    const double ex = double(hi[0]) - lo[0], ey = double(hi[1]) - lo[1], ez = double(hi[2]) - lo[2];
    return 2 * (ex * ey + ey * ez + ez * ex);
  }
};

// A binary node of the first pass.
struct BinNode {
  float lo[3], hi[3];
  std::uint32_t index;  // leaf: first slot; interior: the right child
  std::uint16_t count;  // leaf: number of triangles (> 0); interior: 0
  std::uint16_t axis;
};

// Binned SAH over prims[begin, end): 16 bins per axis on the centroids
// (twice the centroid: lo + hi), all three axes in one pass.
struct Builder {
  std::vector<PrimRef>& prims;
  double pad;
  std::vector<BinNode> nodes;

  void set_box(BinNode& n, const Box& b) const {
    for (int a = 0; a < 3; ++a) {
      n.lo[a] = bvh_detail::round_down(double(b.lo[a]) - pad);
      n.hi[a] = bvh_detail::round_up(double(b.hi[a]) + pad);
    }
  }

  static v4i bin_of(const PrimRef& p, v4f cmin, v4f k, int nb) {
    const v4i b = __builtin_convertvector(((p.lo + p.hi) - cmin) * k, v4i);
    const v4i top = v4i{} + (nb - 1);
    return b < top ? (b > 0 ? b : v4i{}) : top;
  }

  // The boxes of prims[begin, end) and of their (doubled) centroids.
  void bounds(std::uint32_t begin, std::uint32_t end, Box& box, Box& cbox) const {
    for (std::uint32_t i = begin; i < end; ++i) {
      box.grow(prims[i].lo, prims[i].hi);
      const v4f c = prims[i].lo + prims[i].hi;
      cbox.grow(c, c);
    }
  }

  // Builds the subtree over prims[begin, end), whose bounds are box and cbox,
  // on up to `threads` threads; returns its node index.
  std::uint32_t build(std::uint32_t begin, std::uint32_t end, const Box& box, const Box& cbox, int depth, int threads) {
    const std::uint32_t me = std::uint32_t(nodes.size());
    nodes.push_back({});
    set_box(nodes[me], box);
    const std::uint32_t n = end - begin;
    // Up to 4 triangles cost one leaf test whatever their number: a leaf.
    if (n <= std::uint32_t(Bvh::kMaxLeaf)) {
      nodes[me].index = begin;
      nodes[me].count = std::uint16_t(n);
      return me;
    }
    v4f k{};
    for (int a = 0; a < 3; ++a) {
      const float extent = cbox.hi[a] - cbox.lo[a];
      k[a] = extent > 0 ? float(Bvh::kBins) * (1 - 0x1p-20f) / extent : 0.f;
    }
    // Two sets of bins, even and odd primitives, merged after: consecutive
    // primitives often fall in the same bin, and one set would chain every
    // update on the previous one's store. Small ranges use fewer bins (the
    // per-node cost of clearing and sweeping them dominates near the leaves).
    const int nb = int(std::min<std::uint32_t>(Bvh::kBins, std::max<std::uint32_t>(4, n / 2)));
    for (int a = 0; a < 3; ++a) k[a] = k[a] * float(nb) / float(Bvh::kBins);
    Box bins[3][Bvh::kBins], bins2[3][Bvh::kBins];
    std::uint32_t counts[3][Bvh::kBins], counts2[3][Bvh::kBins];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < nb; ++b) {
        bins[a][b] = bins2[a][b] = Box::empty();
        counts[a][b] = counts2[a][b] = 0;
      }
    std::uint32_t i = begin;
    for (; i + 1 < end; i += 2) {
      const PrimRef& p = prims[i];
      const PrimRef& q = prims[i + 1];
      const v4i b = bin_of(p, cbox.lo, k, nb), c = bin_of(q, cbox.lo, k, nb);
      for (int a = 0; a < 3; ++a) {
        bins[a][b[a]].grow(p.lo, p.hi);
        ++counts[a][b[a]];
        bins2[a][c[a]].grow(q.lo, q.hi);
        ++counts2[a][c[a]];
      }
    }
    if (i < end) {
      const v4i b = bin_of(prims[i], cbox.lo, k, nb);
      for (int a = 0; a < 3; ++a) {
        bins[a][b[a]].grow(prims[i].lo, prims[i].hi);
        ++counts[a][b[a]];
      }
    }
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < nb; ++b) {
        bins[a][b].grow(bins2[a][b].lo, bins2[a][b].hi);
        counts[a][b] += counts2[a][b];
      }
    int best_axis = -1, best_bin = -1;
    double best_cost = INFINITY;
    for (int a = 0; a < 3; ++a) {
      if (k[a] == 0) continue;
      double right_area[Bvh::kBins];
      std::uint32_t right_count[Bvh::kBins];
      Box acc = Box::empty();
      std::uint32_t cnt = 0;
      for (int b = nb - 1; b > 0; --b) {
        acc.grow(bins[a][b].lo, bins[a][b].hi);
        cnt += counts[a][b];
        right_area[b] = acc.area();
        right_count[b] = cnt;
      }
      Box left = Box::empty();
      std::uint32_t lcnt = 0;
      for (int b = 0; b < nb - 1; ++b) {
        left.grow(bins[a][b].lo, bins[a][b].hi);
        lcnt += counts[a][b];
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
    // Partition, gathering both sides' bounds on the way (no extra pass).
    std::uint32_t mid = begin;
    Box lbox = Box::empty(), lcbox = lbox, rbox = lbox, rcbox = lbox;
    if (best_axis >= 0 && depth < kMaxSahDepth) {
      std::uint32_t j = end;
      while (mid < j) {
        const PrimRef& p = prims[mid];
        const v4f c = p.lo + p.hi;
        if (bin_of(p, cbox.lo, k, nb)[best_axis] <= best_bin) {
          lbox.grow(p.lo, p.hi);
          lcbox.grow(c, c);
          ++mid;
        } else {
          rbox.grow(p.lo, p.hi);
          rcbox.grow(c, c);
          std::swap(prims[mid], prims[--j]);
        }
      }
    }
    if (mid == begin || mid == end) {
      // All centroids coincide, or a degenerate SAH chain got deep: halve
      // the range, which bounds the remaining depth by log2(n).
      mid = begin + n / 2;
      best_axis = 0;
      lbox = lcbox = rbox = rcbox = Box::empty();
      bounds(begin, mid, lbox, lcbox);
      bounds(mid, end, rbox, rcbox);
    }
    std::uint32_t right;
    if (threads > 1 && n >= kMinParallel) {
      // The right subtree on another thread into its own nodes, appended
      // after the left one with its child indices shifted.
      Builder other{prims, pad, {}};
      std::thread th([&] { other.build(mid, end, rbox, rcbox, depth + 1, threads / 2); });
      build(begin, mid, lbox, lcbox, depth + 1, threads - threads / 2);
      th.join();
      right = std::uint32_t(nodes.size());
      for (BinNode& b : other.nodes)
        if (b.count == 0) b.index += right;
      nodes.insert(nodes.end(), other.nodes.begin(), other.nodes.end());
    } else {
      build(begin, mid, lbox, lcbox, depth + 1, 1);
      right = build(mid, end, rbox, rcbox, depth + 1, 1);
    }
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

  // Emits the 8-wide node for binary node `bi` (interior, or a root leaf).
  std::uint32_t emit(std::uint32_t bi) {
    std::uint32_t kids[Bvh::kWidth];
    int n = 0;
    if (bin[bi].count > 0) {
      kids[n++] = bi;
    } else {
      kids[n++] = bi + 1;
      kids[n++] = bin[bi].index;
      while (n < Bvh::kWidth) {
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
    std::uint32_t child[Bvh::kWidth];
    for (int i = 0; i < Bvh::kWidth; ++i) {
      if (i >= n) {
        child[i] = Bvh::kEmpty;
        continue;
      }
      const BinNode& b = bin[kids[i]];
      child[i] = b.count > 0 ? emit_leaf(b) : emit(kids[i]);
    }
    BvhNode& node = out.nodes[me];
    for (int i = 0; i < Bvh::kWidth; ++i) {
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
  std::vector<PrimRef> prims(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      prims[i].lo[a] = bvh_detail::round_down(lo[i][a]);
      prims[i].hi[a] = bvh_detail::round_up(hi[i][a]);
    }
    const std::uint32_t id = std::uint32_t(i);
    __builtin_memcpy(reinterpret_cast<char*>(&prims[i].lo) + 12, &id, 4);
    prims[i].hi[3] = 0;
  }
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  Builder b{prims, pad, {}};
  b.nodes.reserve(n / 2 + 1);
  Box box = Box::empty(), cbox = box;
  b.bounds(0, std::uint32_t(n), box, cbox);
  b.build(0, std::uint32_t(n), box, cbox, 0, threads);
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = prims[i].id();
  bvh.nodes.reserve(b.nodes.size() / 7 + 1);
  bvh.order.reserve(4 * n);
  Collapser{b.nodes, order, bvh}.emit(0);
  return bvh;
}

}  // namespace ra
