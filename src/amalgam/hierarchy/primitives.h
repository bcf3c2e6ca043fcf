#pragma once
/// \file The primitives of an explicit hierarchy, in leaf order (a leaf's primitives are a
/// contiguous range of ids), stored in one of two forms:
///
/// - **whole**: one 48-byte `Primitive` per id. The build, the bake and edits use this form.
/// - **packed**: what `build_wide` (hierarchy/wide.h) leaves. The triangles of triangle-only
///   leaves live only in the SoA packs the SIMD traversal tests (`TrianglePack4`, their
///   vertices bit for bit); every id keeps a 4-byte slot (its pack and lane, or its index among
///   the primitives kept whole: spheres, boxes, triangles of mixed leaves) and its 4-byte
///   material. A packed triangle costs 36 bytes of pack plus 8 instead of 48 plus 36.
///
/// Both forms give the same `Primitive` for every id (`operator[]`, by value). The packs exist
/// only in the packed form: `edit()` returns to the whole form, after which the hierarchy's
/// SIMD data is stale until `build_wide` runs again (ExplicitHierarchy::wide_nodes checks).

#include <cstdint>
#include <span>
#include <vector>

#include "amalgam/geometry/wide.h"
#include "amalgam/scene/scene.h"
#include "amalgam/util/check.h"

namespace amalgam {

/// A triangle-only leaf's primitives: ids [first, first + count).
struct PrimRange {
  std::uint32_t first = 0;
  std::uint32_t count = 0;
};

class PrimitiveStore {
 public:
  PrimitiveStore() = default;
  PrimitiveStore(std::vector<Primitive> prims)  // NOLINT(google-explicit-constructor)
      : whole_(std::move(prims)) {}

  std::size_t size() const { return packed_ ? size_ : whole_.size(); }
  bool empty() const { return size() == 0; }
  bool packed() const { return packed_; }

  /// Primitive `i` (either form; bit-identical).
  Primitive operator[](std::size_t i) const {
    if (!packed_) return whole_[i];
    const std::uint32_t s = slot_[i];
    if (s & kWhole) return whole_[s & ~kWhole];
    Primitive p{PrimKind::kTriangle, material_[i], {}, {}, {}, 0.0f};
    from_pack(s, p.a, p.b, p.c);
    return p;
  }
  /// The vertices of primitive `i`, a triangle, without the rest of its `Primitive`: the wide
  /// walks' closest hit.
  void triangle(std::size_t i, Vec3& a, Vec3& b, Vec3& c) const {
    if (packed_ && !(slot_[i] & kWhole)) return from_pack(slot_[i], a, b, c);
    const Primitive& p = packed_ ? whole_[slot_[i] & ~kWhole] : whole_[i];
    a = p.a, b = p.b, c = p.c;
  }
  /// Primitive `i` by reference, for loops that read the whole form many times (the bake).
  /// Requires the whole form (`edit()` first): checked in debug builds.
  const Primitive& unpacked(std::size_t i) const {
    AMALGAM_DCHECK(!packed_, "PrimitiveStore::unpacked: the store is packed (edit() first)");
    AMALGAM_DCHECK_LT(i, whole_.size(), "PrimitiveStore::unpacked: index out of range");
    return whole_[i];
  }
  PrimKind kind(std::size_t i) const {
    if (!packed_) return whole_[i].kind;
    const std::uint32_t s = slot_[i];
    return s & kWhole ? whole_[s & ~kWhole].kind : PrimKind::kTriangle;
  }
  std::uint32_t material(std::size_t i) const {
    return packed_ ? material_[i] : whole_[i].material;
  }

  /// The whole form's vector, to read fast or to change (the build, the bake, edits): unpacks
  /// first when packed (the packs are dropped).
  std::vector<Primitive>& edit();
  /// Every primitive as a `Primitive`, in id order (a copy; the store is unchanged).
  std::vector<Primitive> to_vector() const;

  /// Packs the triangles of `leaves` (triangle-only ranges of whole-form ids, each id in at
  /// most one range) into ceil(count / 4) packs per range, consecutive in the ranges' order,
  /// unused lanes NaN; `first_pack[k]` receives the first pack of `leaves[k]`. Every other
  /// primitive is kept whole. Requires the whole form.
  void pack(std::span<const PrimRange> leaves, std::span<std::uint32_t> first_pack);
  /// The packs (packed form; empty otherwise).
  const std::vector<TrianglePack4>& packs() const { return packs_; }

  /// Bytes held (vectors' sizes, not capacities).
  std::size_t bytes() const {
    return whole_.size() * sizeof(Primitive) + slot_.size() * sizeof(std::uint32_t) +
           material_.size() * sizeof(std::uint32_t) + packs_.size() * sizeof(TrianglePack4);
  }

 private:
  void from_pack(std::uint32_t s, Vec3& a, Vec3& b, Vec3& c) const {
    const TrianglePack4& p = packs_[s / kWideLanes];
    const std::uint32_t l = s % kWideLanes;
    a = {p.v[0][0][l], p.v[0][1][l], p.v[0][2][l]};
    b = {p.v[1][0][l], p.v[1][1][l], p.v[1][2][l]};
    c = {p.v[2][0][l], p.v[2][1][l], p.v[2][2][l]};
  }
  static constexpr std::uint32_t kWhole = 0x80000000u;  ///< slot bit: index into whole_
  std::vector<Primitive> whole_;  ///< whole form: all; packed: those not in a pack
  std::size_t size_ = 0;          ///< packed: the number of ids
  bool packed_ = false;
  std::vector<std::uint32_t> slot_;      ///< packed: pack * kWideLanes + lane, or kWhole | index
  std::vector<std::uint32_t> material_;  ///< packed: every id's material
  std::vector<TrianglePack4> packs_;
};

}  // namespace amalgam
