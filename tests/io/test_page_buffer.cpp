// PageArray, the storage of the tile writer's buffers: huge-page aligned when large, kept
// from call to call (the writer fills the same buffer again and again), replaced only when
// a larger one is asked for, and every byte of it usable.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>

#include "io/page_buffer.hpp"

namespace {

using superball::PageArray;

constexpr std::uintptr_t huge_page = std::uintptr_t{2} << 20;

TEST(PageArray, LargeBuffersStartOnAHugePage)
{
    PageArray<std::uint16_t> a;
    const std::uint16_t* p = a.reserve(std::size_t{3} << 20);  // 6 MiB
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % huge_page, 0u);
}

TEST(PageArray, SmallBuffersAreCacheLineAligned)
{
    PageArray<std::uint8_t> a;
    const std::uint8_t* p = a.reserve(100);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % 64, 0u);
}

TEST(PageArray, KeptUntilALargerOneIsAskedFor)
{
    PageArray<std::uint32_t> a;
    EXPECT_EQ(a.data(), nullptr);
    std::uint32_t* p = a.reserve(1000);
    std::iota(p, p + 1000, 0u);
    EXPECT_EQ(a.reserve(1000), p);
    EXPECT_EQ(a.reserve(10), p);
    EXPECT_EQ(a.data(), p);
    EXPECT_EQ(p[999], 999u) << "a smaller request keeps the contents";
    std::uint32_t* q = a.reserve(std::size_t{1} << 20);
    q[(std::size_t{1} << 20) - 1] = 7;  // the last value of the larger buffer is there (ASan checks)
    EXPECT_EQ(a.data(), q);
}

}  // namespace
