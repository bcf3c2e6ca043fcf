// The primitive store's two forms (hierarchy/primitives.h): the packed form that build_wide
// leaves gives every primitive back bit for bit, keeps what the packs cannot hold, and
// returns to the whole form on edit; the bytes it saves are the ones the docs report.

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/io/mesh_import.h"

namespace amalgam {
namespace {

const char* const kWuson = "/usr/share/assimp/models/PLY/Wuson.ply";

bool same_bits(const Primitive& x, const Primitive& y) {
  return x.kind == y.kind && x.material == y.material &&
         std::memcmp(&x.a, &y.a, sizeof(Vec3)) == 0 && std::memcmp(&x.b, &y.b, sizeof(Vec3)) == 0 &&
         std::memcmp(&x.c, &y.c, sizeof(Vec3)) == 0 &&
         std::memcmp(&x.radius, &y.radius, sizeof(float)) == 0;
}

/// Wuson's triangles with materials 0..4 and, every 50th, a sphere: leaves of triangles only
/// (packed) and mixed leaves (kept whole, triangles included).
std::vector<Primitive> mixed() {
  ImportConfig ic;
  std::vector<Primitive> p = import_mesh(kWuson, ic).triangles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    p[i].material = static_cast<std::uint32_t>(i % 5);
    if (i % 50 == 0) p[i] = Primitive::sphere(p[i].a, 0.01f, p[i].material);
  }
  return p;
}

TEST(PrimitiveStore, PackedFormGivesEveryPrimitiveBackBitForBit) {
  std::vector<Surface> mats(5);
  ExplicitHierarchy h = build_explicit(mixed(), mats);
  ASSERT_TRUE(h.prims.packed());
  ASSERT_NE(h.wide_nodes(), nullptr);
  // The whole form of the same build: the store's bytes before build_wide packed them.
  ExplicitHierarchy whole = h;
  const std::vector<Primitive>& ref = whole.prims.edit();
  ASSERT_FALSE(whole.prims.packed());
  EXPECT_EQ(whole.wide_nodes(), nullptr);  // stale SIMD data is never walked
  ASSERT_EQ(ref.size(), h.prims.size());
  std::size_t packed = 0, mixed_tris = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    ASSERT_TRUE(same_bits(h.prims[i], ref[i])) << "primitive " << i;
    EXPECT_EQ(h.prims.kind(i), ref[i].kind);
    EXPECT_EQ(h.prims.material(i), ref[i].material);
  }
  for (std::size_t n = 0; n < h.nodes.size(); ++n) {
    const WideHeader& hd = h.wide.headers[n];
    if (hd.leaf == kWideTriangleLeaf) {
      packed += hd.count;
      for (int c = 0; c < hd.count; ++c) {  // the pack's lane holds the primitive's vertices
        const TrianglePack4& pk = h.prims.packs()[hd.block + static_cast<std::uint32_t>(c) / 4];
        const Primitive& p = ref[hd.first + static_cast<std::uint32_t>(c)];
        for (int a = 0; a < 3; ++a) {
          EXPECT_EQ(pk.v[0][a][c % 4], p.a[a]);
          EXPECT_EQ(pk.v[2][a][c % 4], p.c[a]);
        }
      }
    } else if (hd.leaf == kWideLeaf) {
      for (int c = 0; c < hd.count; ++c)
        mixed_tris += ref[hd.first + static_cast<std::uint32_t>(c)].kind == PrimKind::kTriangle;
    }
  }
  EXPECT_GT(packed, ref.size() / 2);
  EXPECT_GT(mixed_tris, 0u);  // triangles that stay whole are read back too
  // Packed: 8 bytes per primitive, the packs, and the primitives in no pack.
  const std::size_t kept = ref.size() - packed;
  EXPECT_EQ(h.prims.bytes(), ref.size() * 8 + h.prims.packs().size() * sizeof(TrianglePack4) +
                                 kept * sizeof(Primitive));
  EXPECT_EQ(whole.prims.bytes(), ref.size() * sizeof(Primitive));
  // Against the whole primitives plus the same packs beside them (the layout before the store):
  // 48 bytes fewer per packed triangle, 8 more per primitive.
  EXPECT_EQ(whole.prims.bytes() + h.prims.packs().size() * sizeof(TrianglePack4) - h.prims.bytes(),
            packed * sizeof(Primitive) - ref.size() * 8);
}

TEST(PrimitiveStore, BuildWideAgainRepacksTheSameBytes) {
  std::vector<Surface> mats(5);
  ExplicitHierarchy a = build_explicit(mixed(), mats);
  ExplicitHierarchy b = a;
  b.prims.edit();  // whole again, as an edit leaves it
  build_wide(b);
  ASSERT_TRUE(b.prims.packed());
  ASSERT_EQ(a.prims.packs().size(), b.prims.packs().size());
  EXPECT_EQ(std::memcmp(a.prims.packs().data(), b.prims.packs().data(),
                        a.prims.packs().size() * sizeof(TrianglePack4)),
            0);
  ASSERT_EQ(a.wide.headers.size(), b.wide.headers.size());
  EXPECT_EQ(std::memcmp(a.wide.headers.data(), b.wide.headers.data(),
                        a.wide.headers.size() * sizeof(WideHeader)),
            0);
  // build_wide on a packed store unpacks first: the same again.
  build_wide(b);
  for (std::size_t i = 0; i < a.prims.size(); ++i)
    ASSERT_TRUE(same_bits(a.prims[i], b.prims[i])) << "primitive " << i;
}

// Every child reference in the records names its child: a one-pack leaf (the default leaves
// of triangles) by its pack and count, which `pack_node` maps back to the leaf; a mixed leaf by
// its node id; an interior node by its record, whose owner is the child.
TEST(PrimitiveStore, ChildReferencesNameTheirChildren) {
  std::vector<Surface> mats(5);
  const ExplicitHierarchy h = build_explicit(mixed(), mats);
  const WideNodes& w = h.wide;
  ASSERT_NE(h.wide_nodes(), nullptr);
  ASSERT_EQ(w.pack_node.size(), h.prims.packs().size());
  std::size_t pack_refs = 0, node_refs = 0;
  for (std::size_t i = 0; i < h.nodes.size(); ++i) {
    const ExplicitNode& nd = h.nodes[i];
    if (nd.leaf) continue;
    for (int c = 0; c < nd.count; ++c) {
      const std::uint32_t j = nd.first + static_cast<std::uint32_t>(c);
      // The parent's records start at the index its header holds.
      const unsigned char* base = reinterpret_cast<const unsigned char*>(w.pool.data()) +
                                  std::size_t{w.headers[i].block} * kWideRecordBytes +
                                  static_cast<std::size_t>(c / kBoxLanes) * kWideRecordBytes;
      const WideRef r = WideRecord{base}.child(c % kBoxLanes);
      EXPECT_EQ(w.node_of(r), j) << "child " << c << " of node " << i;
      const WideHeader& hd = w.headers[j];
      if (r & kWideRefLeaf && r & kWideRefPack) {
        ++pack_refs;
        EXPECT_EQ(hd.leaf, kWideTriangleLeaf);
        EXPECT_EQ(wide_ref_pack(r), hd.block);
        EXPECT_EQ(wide_ref_pack_count(r), hd.count);
        EXPECT_EQ(w.pack_first(r), hd.first);
      } else if (r & kWideRefLeaf) {
        ++node_refs;
        EXPECT_NE(hd.leaf, kWideTriangleLeaf);  // four triangles at most: one pack
      }
    }
  }
  EXPECT_GT(pack_refs, 100u);
  EXPECT_GT(node_refs, 0u);  // the mixed leaves
}

TEST(PrimitiveStore, AnEditedStoreReadsItsEdits) {
  std::vector<Surface> mats(5);
  ExplicitHierarchy h = build_explicit(mixed(), mats);
  const std::size_t n = h.prims.size();
  const Primitive s = Primitive::sphere({1, 2, 3}, 0.5f, 4);
  h.prims.edit().push_back(s);
  EXPECT_EQ(h.prims.size(), n + 1);
  EXPECT_TRUE(same_bits(h.prims[n], s));
  EXPECT_EQ(h.prims.kind(n), PrimKind::kSphere);
  EXPECT_EQ(h.wide_nodes(), nullptr);
}

}  // namespace
}  // namespace amalgam
