// The element-assembly pipeline: items produced on threads, consumed in
// order by the caller, never more than `slots` ahead.
#include <textile/assembly/ordered_pipeline.h>

#include <gtest/gtest.h>

#include <atomic>
#include <numeric>
#include <stdexcept>
#include <vector>

using textile::assembly::ordered_pipeline;

TEST(OrderedPipeline, ConsumesEveryItemOnceInOrder)
{
  for (int threads : {1, 2, 4})
  {
    const std::size_t n = 1000, slots = 3;
    std::vector<long> slot_value(slots, -1);
    std::vector<std::size_t> consumed;
    std::atomic<int> produced{0};
    ordered_pipeline(
        n, threads, slots,
        [&](std::size_t c, std::size_t slot)
        {
          // the slot must be free: its previous item was consumed
          EXPECT_TRUE(slot_value[slot] == -1 or slot_value[slot] == long(c - slots));
          slot_value[slot] = long(c);
          ++produced;
        },
        [&](std::size_t c, std::size_t slot)
        {
          EXPECT_EQ(slot_value[slot], long(c)); // the item, not a newer one
          consumed.push_back(c);
        });
    EXPECT_EQ(produced, int(n));
    std::vector<std::size_t> expected(n);
    std::iota(expected.begin(), expected.end(), 0);
    EXPECT_EQ(consumed, expected) << threads << " threads";
  }
}

TEST(OrderedPipeline, RethrowsAProducersException)
{
  for (int threads : {1, 3})
    EXPECT_THROW(ordered_pipeline(
                     200, threads, 4,
                     [](std::size_t c, std::size_t)
                     {
                       if (c == 117)
                         throw std::runtime_error("item 117");
                     },
                     [](std::size_t, std::size_t) {}),
                 std::runtime_error);
}
