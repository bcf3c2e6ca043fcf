#pragma once
/// \file What a user describes: surfaces, primitives, lights, camera.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "amalgam/geometry/bbox.h"
#include "amalgam/geometry/intersect.h"
#include "amalgam/math/transform.h"
#include "amalgam/scene/sky.h"

namespace amalgam {

/// How a surface reflects light: Lambertian diffuse plus a normalised Blinn-Phong lobe.
/// No mirror or refraction rays are ever spawned (the paper's setting).
struct Surface {
  Vec3 colour{0.8f, 0.8f, 0.8f};  ///< diffuse albedo, linear RGB (with a texture: its factor)
  float reflectance = 0.0f;       ///< specular weight in [0, 1]
  float shininess = 32.0f;        ///< Blinn-Phong exponent
  /// Base-colour texture (scene/texture.h), an index into the hierarchy's textures, or -1.
  /// The albedo at a hit is `colour` times the texture sampled at the hit's coordinates.
  std::int32_t texture = -1;
};

enum class PrimKind : std::uint8_t { kTriangle, kSphere, kBox };

/// One primitive. Triangle: a, b, c. Sphere: centre a, radius. Box: corners a (lo), b (hi).
struct Primitive {
  PrimKind kind = PrimKind::kTriangle;
  std::uint32_t material = 0;
  Vec3 a, b, c;
  float radius = 0.0f;

  static Primitive triangle(Vec3 a, Vec3 b, Vec3 c, std::uint32_t m = 0) {
    return {PrimKind::kTriangle, m, a, b, c, 0.0f};
  }
  static Primitive sphere(Vec3 centre, float r, std::uint32_t m = 0) {
    return {PrimKind::kSphere, m, centre, {}, {}, r};
  }
  static Primitive box(Vec3 lo, Vec3 hi, std::uint32_t m = 0) {
    return {PrimKind::kBox, m, min(lo, hi), max(lo, hi), {}, 0.0f};
  }
};

/// Ray/primitive test (one intersection test in the paper's sense).
std::optional<SurfaceHit> intersect(const Primitive& prim, const Ray& ray);
/// Tight bounds of a primitive.
Bbox bounds(const Primitive& prim);

enum class LightKind : std::uint8_t { kPoint, kDirectional, kSpot, kSky };

/// A point light (position, intensity in W/sr) or a directional light (direction the light
/// travels, irradiance). Either may have a size, which makes its shadows soft (render/lights.h):
/// a point light with `radius` > 0 is a sphere of that radius, its surface of uniform radiance
/// intensity / (pi radius^2) (the same intensity seen from afar); a directional light with
/// `angle` > 0 comes from a disc of that angular diameter (radians) about -direction, the
/// same irradiance in all. A sized light is sampled with `samples` shadow rays per shading
/// point. Lights are not visible to camera rays.
///
/// A spot light (glTF's KHR_lights_punctual) is a point light shining along `direction` with
/// `intensity` on its axis, scaled off the axis by the glTF falloff: ((cos - cos_outer) /
/// (cos_inner - cos_outer))^2 clamped to [0, 1], cos being that of the angle to the axis.
///
/// The sky (at most one) lights from every direction at infinity: radiance `intensity`, times
/// Environment::sky_map in that direction when there is one (scene/sky.h). It is sampled with
/// `samples` shadow rays per shading point (render/lights.h) and seen by camera rays that miss
/// everything (in place of Environment::background).
struct Light {
  LightKind kind = LightKind::kPoint;
  Vec3 position{};
  Vec3 direction{0, -1, 0};
  Vec3 intensity{1, 1, 1};
  float radius = 0.0f;  ///< point lights: sphere radius (0: a point)
  float angle = 0.0f;   ///< directional lights: angular diameter in radians (0: one direction)
  int samples = 1;      ///< shadow rays per shading point when the light has a size
  float cos_inner = 1.0f, cos_outer = 0.0f;  ///< spot lights: the falloff's cone

  bool sized() const {
    switch (kind) {
      case LightKind::kPoint:
        return radius > 0.0f;
      case LightKind::kDirectional:
        return angle > 0.0f;
      case LightKind::kSpot:
        return false;
      case LightKind::kSky:
        return true;
    }
    return false;
  }
};

/// A pinhole camera.
struct Camera {
  Vec3 position{0, 0, 5};
  Vec3 look_at{0, 0, 0};
  Vec3 up{0, 1, 0};
  float vfov_deg = 45.0f;

  /// The ray through film position (fx, fy) in pixels, (0, 0) being the top-left corner of
  /// a width x height film. The ray carries a cone of one pixel's angular size.
  Ray generate(float fx, float fy, int width, int height) const;
  /// The ray through the film centre: the scene's default ray for `trace`.
  Ray centre_ray(int width, int height) const {
    return generate(width * 0.5f, height * 0.5f, width, height);
  }
};

/// One placement of a mesh: its object-space primitives mapped by `to_world`.
struct Instance {
  Transform to_world;
  std::uint32_t mesh = 0;
};

/// Lights, camera and background: everything but the geometry.
struct Environment {
  std::vector<Light> lights;
  Camera camera;
  Vec3 background{0.05f, 0.05f, 0.08f};
  /// The sky light's radiance map, if it has one (scene/sky.h).
  std::shared_ptr<const SkyMap> sky_map;

  /// What a camera ray that meets nothing sees along unit `dir`: the sky when there is one,
  /// else the background.
  Vec3 seen_toward(Vec3 dir) const;
};

}  // namespace amalgam
