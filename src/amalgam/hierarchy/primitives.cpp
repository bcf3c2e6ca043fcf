#include "amalgam/hierarchy/primitives.h"

#include <limits>

#include "amalgam/util/check.h"
#include "amalgam/util/parallel.h"

namespace amalgam {

std::vector<Primitive>& PrimitiveStore::edit() {
  if (packed_) {
    std::vector<Primitive> all = to_vector();
    slot_ = {};
    material_ = {};
    packs_ = {};
    whole_ = std::move(all);
    packed_ = false;
  }
  return whole_;
}

std::vector<Primitive> PrimitiveStore::to_vector() const {
  if (!packed_) return whole_;
  std::vector<Primitive> all(size_);
  for_each_index(size_, [&](std::size_t i) { all[i] = (*this)[i]; });
  return all;
}

void PrimitiveStore::pack(std::span<const PrimRange> leaves, std::span<std::uint32_t> first_pack) {
  AMALGAM_CHECK(!packed_, "PrimitiveStore::pack: already packed");
  AMALGAM_CHECK_EQ(first_pack.size(), leaves.size(), "PrimitiveStore::pack: one start per leaf");
  AMALGAM_CHECK_LT(whole_.size(), kWhole, "PrimitiveStore::pack: more than 2^31 primitives");
  std::size_t n_packs = 0;
  for (std::size_t k = 0; k < leaves.size(); ++k) {
    first_pack[k] = static_cast<std::uint32_t>(n_packs);
    n_packs += (leaves[k].count + kWideLanes - 1) / kWideLanes;
  }
  AMALGAM_CHECK_LE(n_packs, kWhole / kWideLanes, "PrimitiveStore::pack: too many packs");
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  const std::size_t n = whole_.size();
  std::vector<std::uint32_t> slot(n, kNone), material(n);
  std::vector<TrianglePack4> packs(n_packs);
  for_each_index(n, [&](std::size_t i) { material[i] = whole_[i].material; });
  for_each_index(
      leaves.size(),
      [&](std::size_t k) {
        const PrimRange r = leaves[k];
        for (std::uint32_t c0 = 0, b = 0; c0 < r.count; c0 += kWideLanes, ++b) {
          const std::uint32_t pk = first_pack[k] + b;
          TrianglePack4& pack = packs[pk];
          for (std::uint32_t lane = 0; lane < kWideLanes; ++lane) {
            const std::uint32_t c = c0 + lane;
            const Primitive* p = c < r.count ? &whole_[r.first + c] : nullptr;
            if (p) {
              AMALGAM_CHECK(p->kind == PrimKind::kTriangle, "PrimitiveStore::pack: not a triangle");
              slot[r.first + c] = pk * kWideLanes + lane;
            }
            for (int v = 0; v < 3; ++v) {
              const Vec3 x = !p ? Vec3{kNaN, kNaN, kNaN} : v == 0 ? p->a : v == 1 ? p->b : p->c;
              for (int a = 0; a < 3; ++a) pack.v[v][a][lane] = x[a];
            }
          }
        }
      },
      4096, 1024);
  // The primitives in no pack stay whole, in id order.
  std::vector<Primitive> rest;
  for (std::size_t i = 0; i < n; ++i)
    if (slot[i] == kNone) {
      slot[i] = kWhole | static_cast<std::uint32_t>(rest.size());
      rest.push_back(whole_[i]);
    }
  size_ = n;
  whole_ = std::move(rest);
  slot_ = std::move(slot);
  material_ = std::move(material);
  packs_ = std::move(packs);
  packed_ = true;
}

}  // namespace amalgam
