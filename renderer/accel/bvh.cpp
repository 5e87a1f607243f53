// Builds renderer/accel/bvh.h's 8-wide BVH directly, as Embree's BVHN
// builder does: binned SAH splits (Wald 2007), the child with the largest box
// split next until a node has 8 children; on all threads, the tree not
// depending on their number. Guarantee: every triangle in exactly one leaf,
// and every child box holds its triangles' boxes (rounded outward to float
// from double, then padded by `pad` and rounded outward again).
#include "bvh.h"

#include <immintrin.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <deque>
#include <functional>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "../huge_pages.h"
#include "../workers.h"

namespace ra {
namespace {

// Past this binary depth splits are halvings: the tree is never deeper than
// kMaxSahDepth + 32 binary levels, within the traversal stack (Bvh::kMaxDepth).
constexpr int kMaxSahDepth = 64;
// Splits of the largest ranges (the first levels, before there are subtree
// tasks to share) are binned and partitioned by all threads, in chunks; the
// results are exact, so the same as on one thread. Both sizes follow the
// mesh: n / 8 and n / 32 triangles, within [16K, 128K] and [2K, 32K].
std::uint32_t parallel_split_size(std::size_t n) {
  return std::uint32_t(std::clamp<std::size_t>(n / 8, 1u << 14, 1u << 17));
}
std::uint32_t chunk_size(std::size_t n) { return std::uint32_t(std::clamp<std::size_t>(n / 32, 1u << 11, 1u << 15)); }

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
  // minps / maxps: the same as l < lo ? l : lo (and h > hi ? h : hi), NaN
  // included, in one instruction each (SSE2 code gets 4 from the ?: form).
  void grow(v4f l, v4f h) {
    lo = (v4f)_mm_min_ps((__m128)l, (__m128)lo);
    hi = (v4f)_mm_max_ps((__m128)h, (__m128)hi);
  }
  void grow(const Box& b) { grow(b.lo, b.hi); }
  // Half the surface area; meaningless (but not NaN) for an empty box.
  float half_area() const {
    const v4f e = hi - lo;
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
  }
};

// A range of primitives still to be split: prims [begin, end) of buffer
// `buf` (splits move them from one buffer to the other).
struct Range {
  std::uint32_t begin, end;
  int buf, depth;  // depth: binary splits above it
  Box box, cbox;   // of the triangles and of their (doubled) centroids
  std::uint32_t size() const { return end - begin; }
};

// The binning of a range: 16 bins per axis over its centroid box.
struct Binner {
  v4f cmin, k;
  int nb;
  // Clamped in float before the conversion (SSE2 has no integer min/max):
  // a NaN goes to bin 0, as it did; the centroids lie in the box binned, so
  // only a sum that overflowed to inf lands elsewhere (the last bin).
  v4i bin(const PrimRef& p) const {
    const __m128 x = _mm_max_ps((__m128)(((p.lo + p.hi) - cmin) * k), _mm_setzero_ps());
    return (v4i)_mm_cvttps_epi32(_mm_min_ps(x, _mm_set1_ps(float(nb - 1))));
  }
};

struct Bins {
  Box box[3][Bvh::kBins];
  std::uint32_t count[3][Bvh::kBins];
  void clear(int nb) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < nb; ++b) {
        box[a][b] = Box::empty();
        count[a][b] = 0;
      }
  }
  void merge(const Bins& o, int nb) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < nb; ++b) {
        box[a][b].grow(o.box[a][b]);
        count[a][b] += o.count[a][b];
      }
  }
  std::uint32_t left_count(int axis, int bin) const {
    std::uint32_t c = 0;
    for (int b = 0; b <= bin; ++b) c += count[axis][b];
    return c;
  }
};

// Bins p[0, n) into `out` (cleared here). Large ranges use two sets, even
// and odd primitives, merged after: consecutive primitives often fall in the
// same bin, and one set would chain every update on the previous one's
// store; small ones one set (clearing and merging a second would cost more).
void bin_prims(const PrimRef* p, std::uint32_t n, const Binner& bn, Bins& out) {
  out.clear(bn.nb);
  std::uint32_t i = 0;
  if (n >= 64) {
    Bins other;
    other.clear(bn.nb);
    for (; i + 1 < n; i += 2) {
      const v4i b = bn.bin(p[i]), c = bn.bin(p[i + 1]);
      for (int a = 0; a < 3; ++a) {
        out.box[a][b[a]].grow(p[i].lo, p[i].hi);
        ++out.count[a][b[a]];
        other.box[a][c[a]].grow(p[i + 1].lo, p[i + 1].hi);
        ++other.count[a][c[a]];
      }
    }
    out.merge(other, bn.nb);
  }
  for (; i < n; ++i) {
    const v4i b = bn.bin(p[i]);
    for (int a = 0; a < 3; ++a) {
      out.box[a][b[a]].grow(p[i].lo, p[i].hi);
      ++out.count[a][b[a]];
    }
  }
}

// Moves src[0, n) to dst: those left of the split to dst[l, ...) in order,
// the others to dst[.., r] backwards; grows each side's boxes. (Branching is
// faster than selecting: neighbours in memory are neighbours in space, so
// the side is well predicted.)
void partition(const PrimRef* src, std::uint32_t n, const Binner& bn, int axis, int bin, PrimRef* dst,
               std::uint32_t l, std::uint32_t r, Box& lb, Box& lcb, Box& rb, Box& rcb) {
  for (std::uint32_t i = 0; i < n; ++i) {
    const PrimRef& p = src[i];
    const v4f c = p.lo + p.hi;
    if (bn.bin(p)[axis] <= bin) {
      dst[l++] = p;
      lb.grow(p.lo, p.hi);
      lcb.grow(c, c);
    } else {
      dst[r--] = p;
      rb.grow(p.lo, p.hi);
      rcb.grow(c, c);
    }
  }
}

// round_down / round_up of bvh.h, 4 lanes at once (lane 3 unused).
typedef double v4d __attribute__((vector_size(32)));
typedef long long v4l __attribute__((vector_size(32)));
v4f round4(v4d x, bool up) {
  const v4f f = __builtin_convertvector(x, v4f);
  const v4d back = __builtin_convertvector(f, v4d);
  const v4i off = __builtin_convertvector(up ? (v4l)(back < x) : (v4l)(back > x), v4i);
  const v4f grow = v4f{} + (up ? 1 + 0x1p-23f : 1 - 0x1p-23f), shrink = v4f{} + (up ? 1 - 0x1p-23f : 1 + 0x1p-23f);
  const v4f tiny = v4f{} + (up ? 1e-30f : -1e-30f);
  const v4f big = f > 1e-30f ? f * grow : f < -1e-30f ? f * shrink : f + tiny;
  return off ? big : f;
}

void bounds(const PrimRef* p, std::uint32_t n, Box& box, Box& cbox) {
  for (std::uint32_t i = 0; i < n; ++i) {
    box.grow(p[i].lo, p[i].hi);
    const v4f c = p[i].lo + p[i].hi;
    cbox.grow(c, c);
  }
}

// A minimal pool for one build. The thread that runs build() posts
// sections (count chunks of work) and takes part in them, and posts subtree
// tasks, which the others take while it goes on with the top of the tree.
// Each section lives until the build ends, so a late worker never reads a
// newer one's fields.
class Pool {
 public:
  struct Section {
    const std::function<void(std::uint32_t)>* fn;
    std::uint32_t count;
    std::atomic<std::uint32_t> next{0}, done{0};
  };

  // Runs fn(0 .. count-1) on this thread and any idle ones; returns when all
  // are done.
  void run(std::uint32_t count, const std::function<void(std::uint32_t)>& fn) {
    if (count == 0) return;
    Section* s;
    {
      std::lock_guard<std::mutex> lock(mu_);
      sections_.push_back(std::make_unique<Section>());
      s = sections_.back().get();
    }
    s->fn = &fn;
    s->count = count;
    if (count > 1) {
      cur_.store(s);
      wake();
    }
    work(s);
    for (std::uint32_t d; (d = s->done.load()) != count;) s->done.wait(d);
    rethrow();
  }
  void post(std::function<void()> task) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      queue_.push_back(std::move(task));
      ++posted_;
    }
    wake();
  }
  // Takes part in the posted tasks until all are done.
  void finish_tasks() {
    for (;;) {
      const std::uint32_t e = epoch_.load();
      if (run_task()) continue;
      if (finished_.load() == posted_count()) break;
      epoch_.wait(e);
    }
    rethrow();
  }
  void quit() {
    quit_.store(true);
    wake();
  }
  void worker_loop() {
    for (;;) {
      const std::uint32_t e = epoch_.load();
      if (quit_.load()) return;
      Section* s = cur_.load();
      if (s && s->next.load() < s->count) {
        work(s);
        continue;
      }
      if (run_task()) continue;
      epoch_.wait(e);
    }
  }

 private:
  void wake() {
    epoch_.fetch_add(1);
    epoch_.notify_all();
  }
  std::uint32_t posted_count() {
    std::lock_guard<std::mutex> lock(mu_);
    return posted_;
  }
  void failed() {
    std::lock_guard<std::mutex> lock(mu_);
    if (!error_) error_ = std::current_exception();
  }
  void rethrow() {
    std::lock_guard<std::mutex> lock(mu_);
    if (error_) std::rethrow_exception(error_);
  }
  void work(Section* s) {
    for (std::uint32_t i; (i = s->next.fetch_add(1)) < s->count;) {
      try {
        (*s->fn)(i);
      } catch (...) {
        failed();
      }
      if (s->done.fetch_add(1) + 1 == s->count) s->done.notify_all();
    }
  }
  bool run_task() {
    std::function<void()> t;
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (queue_.empty()) return false;
      t = std::move(queue_.front());
      queue_.pop_front();
    }
    try {
      t();
    } catch (...) {
      failed();
    }
    finished_.fetch_add(1);
    wake();
    return true;
  }
  std::atomic<std::uint32_t> epoch_{0}, finished_{0};
  std::atomic<bool> quit_{false};
  std::atomic<Section*> cur_{nullptr};
  std::mutex mu_;
  std::vector<std::unique_ptr<Section>> sections_;
  std::deque<std::function<void()>> queue_;
  std::uint32_t posted_ = 0;
  std::exception_ptr error_;
};

// Where a subtree's nodes and leaves go: appended to `nodes` and `order`;
// child words are written as if the vectors started at node_base /
// leaf_base (0 while a task builds into its own vectors).
struct Out {
  std::vector<BvhNode>& nodes;
  std::vector<std::uint32_t>& order;
};

// A subtree left to a task: its range, the child word it fills, and what
// it builds.
struct Task {
  Range range;
  std::uint32_t node, slot;
  std::vector<BvhNode> nodes;
  std::vector<std::uint32_t> order;
};

struct Builder {
  PrimRef* buf[2];
  double pad;
  Pool* pool;
  int threads;
  std::uint32_t task_below;  // the top phase leaves ranges smaller than this to tasks
  std::uint32_t parallel_split, chunk;
  std::vector<std::unique_ptr<Task>> tasks;

  // Splits r into l and rr (binned SAH; halving when SAH finds no split).
  void split(const Range& r, Range& l, Range& rr) {
    const std::uint32_t n = r.size();
    const PrimRef* src = buf[r.buf] + r.begin;
    PrimRef* dst = buf[1 - r.buf] + r.begin;
    Binner bn;
    bn.cmin = r.cbox.lo;
    // Small ranges use fewer bins, one per 4 primitives (the per-node cost
    // of clearing and sweeping them dominates near the leaves; the trees'
    // SAH costs for the bunny and the dragon are the same as with n / 2).
    bn.nb = int(std::min<std::uint32_t>(Bvh::kBins, std::max<std::uint32_t>(4, n / 4)));
    bn.k = v4f{};
    for (int a = 0; a < 3; ++a) {
      const float extent = r.cbox.hi[a] - r.cbox.lo[a];
      bn.k[a] = extent > 0 ? float(bn.nb) * (1 - 0x1p-20f) / extent : 0.f;
    }
    const bool par = threads > 1 && n >= parallel_split;
    const std::uint32_t kChunk = chunk;
    const std::uint32_t chunks = par ? (n + kChunk - 1) / kChunk : 1;
    std::vector<Bins> chunk_bins(par ? chunks : 0);
    Bins bins;
    if (par) {
      const std::function<void(std::uint32_t)> f = [&](std::uint32_t c) {
        const std::uint32_t b = c * kChunk;
        bin_prims(src + b, std::min(n - b, kChunk), bn, chunk_bins[c]);
      };
      pool->run(chunks, f);
      bins = chunk_bins[0];
      for (std::uint32_t c = 1; c < chunks; ++c) bins.merge(chunk_bins[c], bn.nb);
    } else {
      bin_prims(src, n, bn, bins);
    }
    // SAH sweep; leaves are tested 4 triangles at a time: cost in blocks of 4.
    int best_axis = -1, best_bin = -1;
    float best_cost = INFINITY;
    for (int a = 0; a < 3; ++a) {
      if (bn.k[a] == 0) continue;
      float right_area[Bvh::kBins];
      std::uint32_t right_count[Bvh::kBins];
      Box acc = Box::empty();
      std::uint32_t cnt = 0;
      for (int b = bn.nb - 1; b > 0; --b) {
        acc.grow(bins.box[a][b]);
        cnt += bins.count[a][b];
        right_area[b] = acc.half_area();
        right_count[b] = cnt;
      }
      Box left = Box::empty();
      std::uint32_t lcnt = 0;
      for (int b = 0; b < bn.nb - 1; ++b) {
        left.grow(bins.box[a][b]);
        lcnt += bins.count[a][b];
        if (lcnt == 0 || right_count[b + 1] == 0) continue;
        const float cost = left.half_area() * float((lcnt + 3) / 4) + right_area[b + 1] * float((right_count[b + 1] + 3) / 4);
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = a;
          best_bin = b;
        }
      }
    }
    std::uint32_t mid;
    Box lb = Box::empty(), lcb = lb, rb = lb, rcb = lb;
    if (best_axis >= 0 && r.depth < kMaxSahDepth) {
      if (par) {
        // Each chunk writes where one pass over all would: its left ones
        // after those of the chunks before it, its right ones likewise from
        // the end backwards.
        std::vector<std::uint32_t> lstart(chunks), rstart(chunks);
        std::uint32_t lsum = 0, rsum = 0;
        for (std::uint32_t c = 0; c < chunks; ++c) {
          const std::uint32_t cn = std::min(n - c * kChunk, kChunk);
          const std::uint32_t lc = chunk_bins[c].left_count(best_axis, best_bin);
          lstart[c] = lsum;
          rstart[c] = n - 1 - rsum;
          lsum += lc;
          rsum += cn - lc;
        }
        mid = lsum;
        std::vector<Box> cb(4 * chunks, Box::empty());
        const std::function<void(std::uint32_t)> f = [&](std::uint32_t c) {
          const std::uint32_t b = c * kChunk;
          partition(src + b, std::min(n - b, kChunk), bn, best_axis, best_bin, dst, lstart[c], rstart[c], cb[4 * c],
                    cb[4 * c + 1], cb[4 * c + 2], cb[4 * c + 3]);
        };
        pool->run(chunks, f);
        for (std::uint32_t c = 0; c < chunks; ++c) {
          lb.grow(cb[4 * c]);
          lcb.grow(cb[4 * c + 1]);
          rb.grow(cb[4 * c + 2]);
          rcb.grow(cb[4 * c + 3]);
        }
      } else {
        partition(src, n, bn, best_axis, best_bin, dst, 0, n - 1, lb, lcb, rb, rcb);
        mid = bins.left_count(best_axis, best_bin);
      }
    } else {
      // All centroids coincide, or a degenerate SAH chain got deep: halve
      // the range, which bounds the remaining depth by log2(n).
      std::memcpy(static_cast<void*>(dst), src, sizeof(PrimRef) * n);
      mid = n / 2;
      bounds(dst, mid, lb, lcb);
      bounds(dst + mid, n - mid, rb, rcb);
    }
    l = Range{r.begin, r.begin + mid, 1 - r.buf, r.depth + 1, lb, lcb};
    rr = Range{r.begin + mid, r.end, 1 - r.buf, r.depth + 1, rb, rcb};
  }

  // A subtree below the top, on one thread into the task's own vectors.
  void run_task(Task& t) const {
    t.nodes.reserve(t.range.size() / 8 + 1);
    t.order.reserve(4 * (t.range.size() / 2 + 1));
    Builder sub{{buf[0], buf[1]}, pad, pool, 1, 0, 0, 0, {}};
    sub.emit(t.range, Out{t.nodes, t.order}, false);
  }

  // A leaf's triangles go to the next 4 slots (unused ones hold kNoTriangle).
  static std::uint32_t emit_leaf(const PrimRef* p, std::uint32_t n, std::vector<std::uint32_t>& order) {
    const std::uint32_t k = std::uint32_t(order.size() / 4);
    for (std::uint32_t i = 0; i < 4; ++i) order.push_back(i < n ? p[i].id() : Bvh::kNoTriangle);
    return Bvh::make_leaf(k, n);
  }

  // Emits the 8-wide node over r (and, depth first, its subtree) into out;
  // returns its index. `top`: ranges below task_below become tasks.
  std::uint32_t emit(const Range& r, Out out, bool top) {
    Range kids[Bvh::kWidth];
    float area[Bvh::kWidth];
    int n = 1;
    kids[0] = r;
    area[0] = r.box.half_area();
    // The child with the largest box is split next (the root always is,
    // unless it is a leaf: a lone leaf gets a node too).
    while (n < Bvh::kWidth) {
      int best = -1;
      float best_area = -1;
      for (int i = 0; i < n; ++i)
        if (kids[i].size() > std::uint32_t(Bvh::kMaxLeaf) && area[i] > best_area) {
          best_area = area[i];
          best = i;
        }
      if (best < 0) break;
      Range a, b;
      split(kids[best], a, b);
      kids[best] = a;
      area[best] = a.box.half_area();
      area[n] = b.box.half_area();
      kids[n++] = b;
    }
    const std::uint32_t me = std::uint32_t(out.nodes.size());
    out.nodes.emplace_back();
    std::uint32_t child[Bvh::kWidth];
    for (int i = 0; i < Bvh::kWidth; ++i) {
      child[i] = Bvh::kEmpty;
      if (i >= n) continue;
      const Range& k = kids[i];
      if (k.size() <= std::uint32_t(Bvh::kMaxLeaf)) {
        child[i] = emit_leaf(buf[k.buf] + k.begin, k.size(), out.order);
      } else if (top && k.size() < task_below) {
        tasks.push_back(std::make_unique<Task>());
        Task* t = tasks.back().get();
        t->range = k;
        t->node = me;
        t->slot = std::uint32_t(i);
        if (threads > 1) pool->post([this, t] { run_task(*t); });
      } else {
        child[i] = emit(k, out, top);
      }
    }
    BvhNode& node = out.nodes[me];
    for (int i = 0; i < Bvh::kWidth; ++i) {
      node.child[i] = child[i];
      v4f lo = v4f{} + INFINITY, hi = v4f{} - INFINITY;
      if (i < n) {
        lo = round4(__builtin_convertvector(kids[i].box.lo, v4d) - pad, false);
        hi = round4(__builtin_convertvector(kids[i].box.hi, v4d) + pad, true);
      }
      for (int a = 0; a < 3; ++a) {
        node.lo[a][i] = lo[a];
        node.hi[a][i] = hi[a];
      }
    }
    return me;
  }
};

// A task's child word moved to its place in the whole tree.
std::uint32_t shifted(std::uint32_t c, std::uint32_t node_off, std::uint32_t leaf_off) {
  if (c == Bvh::kEmpty) return c;
  return Bvh::is_leaf(c) ? c + leaf_off : c + node_off;
}

}  // namespace

Bvh Bvh::build(const std::vector<Vec3d>& lo, const std::vector<Vec3d>& hi, double pad, int threads) {
  return build(
      lo.size(),
      [&](std::size_t begin, std::size_t end, Vec3d* l, Vec3d* h) {
        std::copy(lo.begin() + std::ptrdiff_t(begin), lo.begin() + std::ptrdiff_t(end), l);
        std::copy(hi.begin() + std::ptrdiff_t(begin), hi.begin() + std::ptrdiff_t(end), h);
      },
      pad, threads);
}

Bvh Bvh::build(std::size_t n, const BoxFn& boxes, double pad, int threads) {
  Bvh bvh;
  if (n == 0) return bvh;
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  // Two buffers, uninitialised: splits move primitives from one to the
  // other. The second starts 2 KiB off the first's page offsets: a load and
  // a recent store 4 KiB apart would falsely wait for each other (4K
  // aliasing), and a split streams both at about the same offsets.
  std::unique_ptr<PrimRef[]> store(new PrimRef[2 * n + 64]);
  advise_huge_pages(store.get(), sizeof(PrimRef) * (2 * n + 64));
  PrimRef* const a = store.get();
  PrimRef* const b = a + n + 64;
  Pool pool;
  Builder bld{{a, b}, pad, &pool, threads, 0, parallel_split_size(n), chunk_size(n), {}};
  const std::size_t kChunk = bld.chunk;
  // The top of the tree is built by one thread (its large splits by all);
  // the subtrees below task_below are tasks the others take meanwhile,
  // each built into its own vectors and placed after the top's nodes in the
  // order the top met them. A function of n only, so the tree is the same
  // for every thread count.
  bld.task_below = std::uint32_t(std::max<std::size_t>(2048, n / 128));
  auto top = [&] {
    const std::uint32_t chunks = std::uint32_t((n + kChunk - 1) / kChunk);
    std::vector<Box> cb(2 * chunks, Box::empty());
    const std::function<void(std::uint32_t)> refs = [&](std::uint32_t c) {
      const std::size_t end = std::min(n, std::size_t(c + 1) * kChunk);
      constexpr std::size_t kPiece = 512;
      Vec3d lo[kPiece], hi[kPiece];
      for (std::size_t b0 = std::size_t(c) * kChunk; b0 < end; b0 += kPiece) {
        const std::size_t e0 = std::min(end, b0 + kPiece);
        boxes(b0, e0, lo, hi);
        for (std::size_t i = b0; i < e0; ++i) {
          PrimRef& p = a[i];
          const Vec3d& l = lo[i - b0];
          const Vec3d& h = hi[i - b0];
          p.lo = round4(v4d{l.x, l.y, l.z, 0}, false);
          p.hi = round4(v4d{h.x, h.y, h.z, 0}, true);
          const std::uint32_t id = std::uint32_t(i);
          __builtin_memcpy(reinterpret_cast<char*>(&p.lo) + 12, &id, 4);
          p.hi[3] = 0;
        }
      }
      bounds(&a[std::size_t(c) * kChunk], std::uint32_t(end - std::size_t(c) * kChunk), cb[2 * c], cb[2 * c + 1]);
    };
    pool.run(chunks, refs);
    Range root{0, std::uint32_t(n), 0, 0, Box::empty(), Box::empty()};
    for (std::uint32_t c = 0; c < chunks; ++c) {
      root.box.grow(cb[2 * c]);
      root.cbox.grow(cb[2 * c + 1]);
    }
    bvh.nodes.reserve(n / 8 + 1);
    advise_huge_pages(bvh.nodes.data(), (n / 8 + 1) * sizeof(BvhNode));
    bvh.order.reserve(4 * (n / 2 + 1));
    bld.emit(root, Out{bvh.nodes, bvh.order}, true);
    if (threads == 1) {
      // The tasks in order, straight after the top: where the copies below
      // would put them.
      for (auto& t : bld.tasks) {
        bvh.nodes[t->node].child[t->slot] = std::uint32_t(bvh.nodes.size());
        Builder sub{{a, b}, pad, &pool, 1, 0, 0, 0, {}};
        sub.emit(t->range, Out{bvh.nodes, bvh.order}, false);
      }
      return;
    }
    pool.finish_tasks();
    // The tasks' nodes and leaves after the top's, in the order the top
    // met them.
    std::vector<std::uint32_t> node_off(bld.tasks.size()), leaf_off(bld.tasks.size());
    std::size_t nodes = bvh.nodes.size(), slots = bvh.order.size();
    for (std::size_t i = 0; i < bld.tasks.size(); ++i) {
      node_off[i] = std::uint32_t(nodes);
      leaf_off[i] = std::uint32_t(slots / 4);
      nodes += bld.tasks[i]->nodes.size();
      slots += bld.tasks[i]->order.size();
      bvh.nodes[bld.tasks[i]->node].child[bld.tasks[i]->slot] = node_off[i];
    }
    bvh.nodes.resize(nodes);
    bvh.order.resize(slots);
    const std::function<void(std::uint32_t)> place = [&](std::uint32_t i) {
      Task& t = *bld.tasks[i];
      BvhNode* dst = bvh.nodes.data() + node_off[i];
      for (std::size_t j = 0; j < t.nodes.size(); ++j) {
        dst[j] = t.nodes[j];
        for (std::uint32_t& c : dst[j].child) c = shifted(c, node_off[i], leaf_off[i]);
      }
      std::memcpy(bvh.order.data() + std::size_t(leaf_off[i]) * 4, t.order.data(), t.order.size() * 4);
      std::vector<BvhNode>().swap(t.nodes);
      std::vector<std::uint32_t>().swap(t.order);
    };
    pool.run(std::uint32_t(bld.tasks.size()), place);
  };
  std::atomic<int> ids{0};
  run_workers(threads, [&] {
    if (ids.fetch_add(1) != 0) {
      pool.worker_loop();
      return;
    }
    struct Quit {
      Pool& p;
      ~Quit() { p.quit(); }
    } quit{pool};
    top();
  });
  return bvh;
}

}  // namespace ra
