#include "core/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>

#include "core/light.h"

namespace lc {
namespace {

// Past the allocator's threshold, so that the block is the huge-page kind.
constexpr size_t kLarge = (HugePageAllocator<uint32_t>::kThreshold / sizeof(uint32_t)) * 2;

// A HugeVector keeps std::vector's value-initialisation: elements that resize() adds are
// T(), even where the block held other values before (LightSet::lights relies on Light's
// defaults). A BigVector leaves them unwritten, for the tree builders that write them all.
TEST(HugePages, HugeVectorValueInitialisesWhatResizeAdds) {
  HugeVector<Light> lights;
  lights.reserve(kLarge / 4);
  Light odd;
  odd.position = Vec3(1, 2, 3);
  odd.type = LightType::Spot;
  odd.group = 77;
  lights.assign(lights.capacity(), odd);
  const Light* block = lights.data();
  lights.clear();
  lights.resize(lights.capacity());
  ASSERT_EQ(lights.data(), block);  // the same block, which held `odd` everywhere
  for (const Light& l : lights) {
    ASSERT_EQ(l.type, LightType::Omni);
    ASSERT_EQ(l.group, 0);
    ASSERT_EQ(l.position, Vec3(0.0f));
  }

  BigVector<uint32_t> raw(kLarge, 5u);  // resize(n, value) writes
  raw.clear();
  raw.resize(kLarge);  // unwritten: what the block held stays
  EXPECT_EQ(raw[kLarge / 2], 5u);
}

// moveToHugePages puts a large array on a new block with every element unchanged, and
// leaves a small one where it is.
TEST(HugePages, MoveToHugePagesKeepsTheElements) {
  BigVector<uint32_t> v(kLarge + 12345);  // not a whole number of 2 MiB pieces
  for (size_t i = 0; i < v.size(); ++i) v[i] = uint32_t(i * 2654435761u);
  const uint32_t* before = v.data();
  moveToHugePages(v);
  ASSERT_EQ(v.size(), kLarge + 12345);
  EXPECT_NE(v.data(), before);
  for (size_t i = 0; i < v.size(); ++i) ASSERT_EQ(v[i], uint32_t(i * 2654435761u)) << i;

  BigVector<uint32_t> small(100, 9u);
  const uint32_t* at = small.data();
  moveToHugePages(small);
  EXPECT_EQ(small.data(), at);
  EXPECT_EQ(small[99], 9u);
}

}  // namespace
}  // namespace lc
