// What the CPU renderers (the reference, the path tracer) share: threads, counter-based random
// numbers, the Embree scene of the mesh.
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "lucent/core/error.h"
#include "lucent/render/scene.h"

namespace lucent::render::detail {

using Vec3d = Eigen::Vector3d;
using Clock = std::chrono::steady_clock;
constexpr double kInf = std::numeric_limits<double>::infinity();

inline double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// ---------------------------------------------------------------------------------------------
// Threads: work items handed out in chunks from an atomic counter; results never depend on which
// thread ran what.

inline void parallel_for(std::size_t count, int threads, std::size_t chunk,
                         const std::function<void(std::size_t, std::size_t)>& body,
                         const std::function<void(std::size_t)>& on_progress = {}) {
  std::atomic<std::size_t> next{0}, done{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&](bool reporter) {
    try {
      for (;;) {
        const std::size_t begin = next.fetch_add(chunk);
        if (begin >= count) break;
        const std::size_t end = std::min(count, begin + chunk);
        body(begin, end);
        const std::size_t total = done.fetch_add(end - begin) + (end - begin);
        if (reporter && on_progress) on_progress(total);
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = count;
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, false);
  work(true);
  for (auto& thread : pool) thread.join();
  if (failure) std::rethrow_exception(failure);
}

// Counter-based random numbers: sample k of pass p of seed s is the same whatever thread draws it.
inline std::uint64_t mix(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
inline double uniform01(std::uint64_t key) {
  return double(mix(key) >> 11) * 0x1.0p-53;
}

// ---------------------------------------------------------------------------------------------
// Embree scene of the mesh.

class RayScene {
 public:
  explicit RayScene(const Mesh& mesh) {
    device_ = rtcNewDevice("verbose=0");
    if (!device_) throw Error("render: cannot create an Embree device");
    scene_ = rtcNewScene(device_);
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.positions.size()));
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh.positions[i][k];
    }
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh.triangles.size()));
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      for (int k = 0; k < 3; ++k) indices[3 * t + k] = mesh.triangles[t][k];
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene_);
  }
  ~RayScene() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  /// Nearest hit: triangle index and Embree's barycentrics (u, v) of vertices 1 and 2; false if
  /// none.
  bool intersect(const Vec3f& origin, const Vec3f& direction, unsigned& triangle, float& u,
                 float& v) const {
    float t = 0;
    return intersect_segment(origin, direction, 0.0f, std::numeric_limits<float>::infinity(),
                             triangle, u, v, t);
  }

  /// Nearest hit along the ray in (t_near, t_far): triangle, barycentrics and distance t.
  bool intersect_segment(const Vec3f& origin, const Vec3f& direction, float t_near, float t_far,
                         unsigned& triangle, float& u, float& v, float& t) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    set_ray(rh.ray, origin, direction, t_far);
    rh.ray.tnear = t_near;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    triangle = rh.hit.primID;
    u = rh.hit.u;
    v = rh.hit.v;
    t = rh.ray.tfar;
    return true;
  }

  bool occluded(const Vec3f& origin, const Vec3f& direction, double max_distance) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray{};
    set_ray(ray, origin, direction, max_distance);
    rtcOccluded1(scene_, &context, &ray);
    return ray.tfar < 0;  // Embree sets tfar = -inf on a hit
  }

 private:
  static void set_ray(RTCRay& ray, const Vec3f& o, const Vec3f& d, double tfar) {
    ray.org_x = o.x();
    ray.org_y = o.y();
    ray.org_z = o.z();
    ray.dir_x = d.x();
    ray.dir_y = d.y();
    ray.dir_z = d.z();
    ray.tnear = 0.0f;
    ray.tfar = std::isinf(tfar) ? std::numeric_limits<float>::infinity() : float(tfar);
    ray.mask = ~0u;
    ray.flags = 0;
    ray.time = 0.0f;
  }

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

}  // namespace lucent::render::detail
