// MeshArrivals: a setup waits for its own body's mesh only, and every waiter is released when
// the loading is abandoned.

#include "coupling/mesh_arrivals.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <stdexcept>
#include <thread>

namespace robin {
namespace {

TEST(MeshArrivals, AWaiterWaitsForItsOwnBodyOnly) {
  MeshArrivals arrivals(2);
  EXPECT_FALSE(arrivals.first_arrival().has_value());
  std::atomic<bool> second_arrived = false;
  std::future<bool> waiter = std::async(std::launch::async, [&] {
    const bool arrived = arrivals.wait(1);
    EXPECT_TRUE(second_arrived.load());  // not released by body 0's arrival
    return arrived;
  });
  arrivals.arrive(0);
  EXPECT_EQ(waiter.wait_for(std::chrono::milliseconds(50)), std::future_status::timeout);
  EXPECT_TRUE(arrivals.wait(0));  // an arrived body does not block
  const auto first = arrivals.first_arrival();
  ASSERT_TRUE(first.has_value());
  second_arrived = true;
  arrivals.arrive(1);
  EXPECT_TRUE(waiter.get());
  EXPECT_EQ(arrivals.first_arrival(), first);
  ASSERT_TRUE(arrivals.last_arrival().has_value());
  EXPECT_GE(*arrivals.last_arrival(), *first);
}

TEST(MeshArrivals, AbandoningReleasesEveryWaiterWithFalse) {
  MeshArrivals arrivals(3);
  arrivals.arrive(2);
  std::future<bool> first = std::async(std::launch::async, [&] { return arrivals.wait(0); });
  std::future<bool> second = std::async(std::launch::async, [&] { return arrivals.wait(1); });
  arrivals.abandon();
  EXPECT_FALSE(first.get());
  EXPECT_FALSE(second.get());
  EXPECT_TRUE(arrivals.wait(2));  // what arrived before stays arrived
  EXPECT_THROW(arrivals.arrive(3), std::out_of_range);
  EXPECT_THROW(arrivals.wait(3), std::out_of_range);
}

}  // namespace
}  // namespace robin
