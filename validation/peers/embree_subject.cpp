// Embree 3's own ray/triangle answer as an audit subject: rtcIntersect1 on a
// scene holding the one triangle under test, float (Embree's API), default
// scene flags or RTC_SCENE_FLAG_ROBUST.
//
// Source: Embree 3 API (rtcore_scene.h, rtcore_ray.h; Debian libembree-dev
// 3.13), as its users call it. Guarantee: none beyond Embree's own. Its
// documentation says the default kernels trade arithmetic accuracy for speed
// and the robust flag "avoids optimizations that reduce arithmetic accuracy"
// (Mitsuba switches it on for rays through shared edges); the audit measures
// what each gives.
//
// One scene per thread and flag is kept and rebuilt for every test: the
// vertex buffer rewritten in place, rtcUpdateGeometryBuffer, rtcCommitGeometry
// and rtcCommitScene: about 3 us of CPU a test in the audit (README.md); in a
// standalone loop a refit build quality and RTC_BUILD_QUALITY_LOW were both
// slower than the default (13 and 22 us against 11, a loaded machine). The thread's
// floating-point modes are left as they are: Embree recommends flush-to-zero
// and denormals-are-zero, which would change the other subjects' arithmetic
// on the same thread.
#include "peers.h"

#if RAYAUDIT_HAVE_EMBREE
#include <embree3/rtcore.h>

#include <memory>
#include <stdexcept>

namespace ra::peers {
namespace {

// One device for the process (devices are thread-safe; scenes are not shared).
RTCDevice device() {
  static const RTCDevice d = [] {
    RTCDevice dev = rtcNewDevice(nullptr);
    if (!dev) throw std::runtime_error("Embree: rtcNewDevice failed (libembree3)");
    return dev;
  }();
  return d;
}

// A scene of one triangle whose three vertices are rewritten before each test.
class OneTriangle {
 public:
  explicit OneTriangle(bool robust) {
    RTCDevice dev = device();
    scene_ = rtcNewScene(dev);
    if (robust) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    geom_ = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    // rtcSetNewGeometryBuffer pads the buffer for Embree's 16-byte loads.
    v_ = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom_, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3));
    auto* idx = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom_, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 1));
    idx[0] = 0, idx[1] = 1, idx[2] = 2;
    v_[0] = v_[1] = v_[2] = v_[3] = v_[4] = v_[5] = v_[6] = v_[7] = v_[8] = 0;
    rtcCommitGeometry(geom_);
    rtcAttachGeometry(scene_, geom_);
    if (rtcGetDeviceError(dev) != RTC_ERROR_NONE)
      throw std::runtime_error("Embree: making a one-triangle scene failed");
  }
  OneTriangle(const OneTriangle&) = delete;
  OneTriangle& operator=(const OneTriangle&) = delete;
  ~OneTriangle() {
    rtcReleaseGeometry(geom_);
    rtcReleaseScene(scene_);
  }

  std::optional<TriangleHit<float>> hit(const Rayf& r, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
    const Vec3f* p[3] = {&a, &b, &c};
    for (int k = 0; k < 3; ++k) v_[3 * k] = p[k]->x, v_[3 * k + 1] = p[k]->y, v_[3 * k + 2] = p[k]->z;
    rtcUpdateGeometryBuffer(geom_, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geom_);
    rtcCommitScene(scene_);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray.org_x = r.o.x, rh.ray.org_y = r.o.y, rh.ray.org_z = r.o.z;
    rh.ray.dir_x = r.d.x, rh.ray.dir_y = r.d.y, rh.ray.dir_z = r.d.z;
    rh.ray.tnear = r.tmin;
    rh.ray.tfar = r.tmax;
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    // Embree's u, v weigh vertices 1 and 2: our b1, b2.
    return TriangleHit<float>{rh.ray.tfar, rh.hit.u, rh.hit.v};
  }

 private:
  RTCScene scene_ = nullptr;
  RTCGeometry geom_ = nullptr;
  float* v_ = nullptr;
};

OneTriangle& scene_for(bool robust) {
  thread_local std::unique_ptr<OneTriangle> scenes[2];
  auto& s = scenes[robust ? 1 : 0];
  if (!s) s = std::make_unique<OneTriangle>(robust);
  return *s;
}

}  // namespace

bool have_embree() { return true; }

audit::TriangleSubject embree_subject(bool robust) {
  return audit::triangle_subject<float>(robust ? "embree-robust" : "embree",
                                        [robust](const Rayf& r, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
                                          return scene_for(robust).hit(r, a, b, c);
                                        });
}

}  // namespace ra::peers

#else  // a build without Embree: peers() lists embree and embree-robust as missing

namespace ra::peers {
bool have_embree() { return false; }
audit::TriangleSubject embree_subject(bool) { return {}; }
}  // namespace ra::peers

#endif
