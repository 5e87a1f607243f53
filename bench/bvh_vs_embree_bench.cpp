// Development yardstick for issue 17: rayaudit's BVH against Embree 3 (default
// build quality, non-robust, device "threads=1") on the same rays, one thread.
// Primary rays: 1280x960 through the pixel centres of the camera that frames
// the mesh (apply_content_defaults); shadow rays: from each primary hit (o + t d
// in double) towards a light at the camera, window [1e-4, 1 - 1e-4] of the
// segment. Prints Mrays/s (per second of this thread's CPU time) of both (median of --reps runs), the ratio, the hit
// counts of both, and the build times. `rayaudit bench`'s peer/embree rows are
// the official figures; this is the quick loop for tuning the traversal.
//   bvh_vs_embree_bench MESH.obj [reps] [float|double] [method]
#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <thread>
#include <vector>

#include "accel/bvh.h"
#include "camera.h"
#include "render.h"
#include "scene.h"

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// This thread's CPU time: the machine is shared, wall time would count the
// other processes' slices (both tracers run on this thread only).
double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s MESH.obj [reps] [float|double] [method]\n", argv[0]);
    return 2;
  }
  const int reps = argc > 2 ? std::atoi(argv[2]) : 5;
  const bool dbl = argc > 3 ? std::string(argv[3]) == "double" : false;
  const std::string method = argc > 4 ? argv[4] : "moller";
  ra::Scene scene = ra::load_scene(argv[1]);
  scene.width = 1280;
  scene.height = 960;
  ra::apply_content_defaults(scene);
  const ra::TriangleSet& mesh = *scene.objects.at(0).mesh;
  const ra::Camera cam(scene.camera, scene.width, scene.height);
  const ra::Vec3d light = cam.origin();

  std::vector<ra::Ray<double>> primary;
  primary.reserve(std::size_t(scene.width) * scene.height);
  for (int j = 0; j < scene.height; ++j)
    for (int i = 0; i < scene.width; ++i) primary.push_back(cam.ray(i + 0.5, j + 0.5));

  // Embree scene.
  RTCDevice dev = rtcNewDevice("threads=1");
  double t0 = cpu_now();
  RTCScene es = rtcNewScene(dev);
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), mesh.positions.size()));
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    for (int a = 0; a < 3; ++a) vb[3 * i + a] = float(mesh.positions[i][a]);
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(unsigned), mesh.triangles.size()));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int a = 0; a < 3; ++a) ib[3 * i + a] = unsigned(mesh.triangles[i].v[a]);
  rtcCommitGeometry(g);
  rtcAttachGeometry(es, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(es);
  const double embree_build = cpu_now() - t0;
  // Our BVH alone, from the same boxes the tracer gives it (median of reps).
  std::vector<double> builds, builds_all, embree_all;
  {
    std::vector<ra::Vec3d> lo, hi;
    for (const auto& t : mesh.triangles) {
      const auto& a = mesh.positions[t.v[0]];
      const auto& b = mesh.positions[t.v[1]];
      const auto& c = mesh.positions[t.v[2]];
      lo.push_back(ra::vmin(a, ra::vmin(b, c)));
      hi.push_back(ra::vmax(a, ra::vmax(b, c)));
    }
    for (int k = 0; k < reps; ++k) {
      const double s = cpu_now();
      const ra::Bvh bvh = ra::Bvh::build(lo, hi, 1e-5, 1);
      builds.push_back(cpu_now() - s);
    }
    for (int k = 0; k < reps; ++k) {
      const double s = now();
      const ra::Bvh bvh = ra::Bvh::build(lo, hi, 1e-5, 0);
      builds_all.push_back(now() - s);
    }
  }
  // Embree's build on its default device (all cores), wall time.
  for (int k = 0; k < reps; ++k) {
    RTCDevice d2 = rtcNewDevice(nullptr);
    const double s = now();
    RTCScene s2 = rtcNewScene(d2);
    RTCGeometry g2 = rtcNewGeometry(d2, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g2, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vb, 0, 3 * sizeof(float),
                               mesh.positions.size());
    rtcSetSharedGeometryBuffer(g2, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, ib, 0, 3 * sizeof(unsigned),
                               mesh.triangles.size());
    rtcCommitGeometry(g2);
    rtcAttachGeometry(s2, g2);
    rtcReleaseGeometry(g2);
    rtcCommitScene(s2);
    embree_all.push_back(now() - s);
    rtcReleaseScene(s2);
    rtcReleaseDevice(d2);
  }

  ra::RenderOptions opt;
  opt.use_double = dbl;
  opt.triangle_method = method;
  opt.threads = 1;
  opt.progress = false;
  t0 = now();
  ra::Tracer tracer(scene, opt);
  const double ours_build = now() - t0;

  // Shadow rays from our hits (both tracers get the same ones).
  std::vector<ra::Ray<double>> shadow;
  for (const auto& r : primary)
    if (auto h = tracer.intersect(r)) {
      const ra::Vec3d p = r.at(h->t);
      shadow.push_back({p, light - p, 1e-4, 1 - 1e-4});
    }

  auto embree_primary = [&](long& hits) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    hits = 0;
    for (const auto& r : primary) {
      RTCRayHit rh{};
      rh.ray.org_x = float(r.o.x), rh.ray.org_y = float(r.o.y), rh.ray.org_z = float(r.o.z);
      rh.ray.dir_x = float(r.d.x), rh.ray.dir_y = float(r.d.y), rh.ray.dir_z = float(r.d.z);
      rh.ray.tnear = 0, rh.ray.tfar = INFINITY, rh.ray.mask = ~0u;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(es, &ctx, &rh);
      hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
  };
  auto embree_shadow = [&](long& hits) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    hits = 0;
    for (const auto& r : shadow) {
      RTCRay ray{};
      ray.org_x = float(r.o.x), ray.org_y = float(r.o.y), ray.org_z = float(r.o.z);
      ray.dir_x = float(r.d.x), ray.dir_y = float(r.d.y), ray.dir_z = float(r.d.z);
      ray.tnear = float(r.tmin), ray.tfar = float(r.tmax), ray.mask = ~0u;
      rtcOccluded1(es, &ctx, &ray);
      hits += ray.tfar < 0;
    }
  };
  auto ours_primary = [&](long& hits) {
    hits = 0;
    for (const auto& r : primary) hits += tracer.intersect(r).has_value();
  };
  auto ours_shadow = [&](long& hits) {
    hits = 0;
    for (const auto& r : shadow) hits += tracer.occluded(r);
  };
  auto time = [&](auto&& f, long& hits, std::size_t n) {
    std::vector<double> rates;
    for (int k = 0; k < reps; ++k) {
      const double s = cpu_now();
      f(hits);
      rates.push_back(double(n) / (cpu_now() - s) / 1e6);
    }
    return median(rates);
  };
  // Rays pointing away from the mesh: what a ray costs before any box.
  std::vector<ra::Ray<double>> away;
  for (const auto& r : primary) away.push_back({r.o, -r.d, 0, INFINITY});
  auto embree_away = [&](long& hits) {
    std::swap(primary, away);
    embree_primary(hits);
    std::swap(primary, away);
  };
  auto ours_away = [&](long& hits) {
    std::swap(primary, away);
    ours_primary(hits);
    std::swap(primary, away);
  };
  long he = 0, ho = 0, se = 0, so = 0, ae = 0, ao = 0;
  const double ea = time(embree_away, ae, away.size());
  const double oa = time(ours_away, ao, away.size());
  const double ep = time(embree_primary, he, primary.size());
  const double op = time(ours_primary, ho, primary.size());
  const double esr = time(embree_shadow, se, shadow.size());
  const double osr = time(ours_shadow, so, shadow.size());
  std::printf("%s %zu tris, %s %s\n", argv[1], mesh.triangles.size(), method.c_str(), dbl ? "double" : "float");
  std::printf("build  embree %.3f s  ours: BVH %.3f s (CPU, 1 thread), tracer %.3f s wall (prepare + BVH)\n",
              embree_build, median(builds), ours_build);
  std::printf("build, all cores, wall: embree %.3f s  ours BVH %.3f s\n", median(embree_all), median(builds_all));
  std::printf("primary embree %.2f Mrays/s  ours %.2f  ratio %.3f  hits %ld / %ld\n", ep, op, op / ep, he, ho);
  std::printf("shadow  embree %.2f Mrays/s  ours %.2f  ratio %.3f  occluded %ld / %ld of %zu\n", esr, osr, osr / esr,
              se, so, shadow.size());
  // Two threads on alternate primary rays: rays per second of each
  // thread's own CPU time, summed (a shared machine cannot give two idle
  // cores; this shows whether the threads slow each other down).
  {
    const std::size_t half = primary.size() / 2;
    double cpu[2] = {0, 0};
    std::vector<double> rates2;
    for (int k = 0; k < reps; ++k) {
      auto run = [&](int w) {
        const double s = cpu_now();
        long h = 0;
        // Alternate rays, so both threads get the same mix of hits and misses.
        for (std::size_t i = std::size_t(w); i < 2 * half; i += 2) h += tracer.intersect(primary[i]).has_value();
        cpu[w] = cpu_now() - s + 0 * double(h);
      };
      std::thread t1(run, 1);
      run(0);
      t1.join();
      rates2.push_back((double(half) / cpu[0] + double(half) / cpu[1]) / 1e6);
    }
    std::printf("primary, 2 threads: ours %.2f Mrays/s (sum over threads of rays per CPU second) = %.2f x 1 thread\n",
                median(rates2), median(rates2) / op);
  }
  std::printf("away    embree %.2f Mrays/s  ours %.2f  ratio %.3f  (rays missing everything)\n", ea, oa, oa / ea);
  rtcReleaseScene(es);
  rtcReleaseDevice(dev);
  return 0;
}
