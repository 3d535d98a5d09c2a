/// The deterministic reductions (kernels/core/reduce.hpp): the documented tree to the bit, on every level count, with
/// maxima alongside, and the W-lane item functions giving what one item at a time gives.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "tree_sum.hpp"

using namespace dem;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Values of mixed signs over twelve decades: any other order of the sum rounds differently.
std::vector<double> awkward_values(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> mant(-1.0, 1.0), expo(-6.0, 6.0);
  std::vector<double> v(n);
  for (double& x : v) x = mant(rng) * std::pow(10.0, expo(rng));
  return v;
}

ScalarView device_copy(const std::vector<double>& v) {
  ScalarView d("values", v.size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < v.size(); ++i) h(i) = v[i];
  Kokkos::deep_copy(d, h);
  return d;
}

// Functors, not lambdas: nvcc allows no device lambda in a test body.
struct ValueAndMagnitude {
  ScalarView d;
  KOKKOS_INLINE_FUNCTION void operator()(const int i, Real* v) const {
    v[0] = d(i);
    v[1] = d(i) > 0 ? d(i) : -d(i);
  }
};

struct Ones {
  KOKKOS_INLINE_FUNCTION void operator()(const int, Real* v) const { v[0] = v[1] = 1; }
};

TEST(Reduce, SumsFollowTheDocumentedTreeToTheBit) {
  // One item, one block, a block and one, and three levels (256^2 + 1 items).
  for (const int n : {1, 3, kReduceBlock, kReduceBlock + 1, 5000, kReduceBlock * kReduceBlock + 1}) {
    const std::vector<double> vals = awkward_values(n, 7u + n);
    const ScalarView d = device_copy(vals);
    Real out[2];
    deterministic_reduce<1, 1>("test::reduce", n, ValueAndMagnitude{d}, out);
    double sequential = 0, largest = 0;
    for (double x : vals) sequential += x, largest = std::max(largest, std::fabs(x));
    EXPECT_TRUE(same_bits(out[0], test::tree_sum(vals))) << n << " items: " << out[0] << " vs " << test::tree_sum(vals);
    EXPECT_EQ(out[1], largest) << n << " items";
    // The test can tell orders apart: for these values, the sequential sum is another number.
    if (n > kReduceBlock) EXPECT_FALSE(same_bits(test::tree_sum(vals), sequential)) << n << " items";
  }
}

TEST(Reduce, NoItemsGiveZeros) {
  Real out[2] = {5, 5};
  deterministic_reduce<1, 1>("test::reduce", 0, Ones{}, out);
  EXPECT_EQ(out[0], 0);
  EXPECT_EQ(out[1], 0);
}

/// W items at once, as the leapfrog's lanes give them: the same bits as one at a time, for counts that end
/// inside a group.
struct Squares {
  ScalarView d;
  KOKKOS_INLINE_FUNCTION void operator()(const int i0, const int count, Real (*vals)[1]) const {
    for (int k = 0; k < count; ++k) vals[k][0] = d(i0 + k) * d(i0 + k);
  }
};

TEST(Reduce, LaneGroupsGiveTheBitsOfOneItemAtATime) {
  for (const int n : {2, 4 * kReduceBlock + 3}) {
    const std::vector<double> vals = awkward_values(n, 99u);
    const ScalarView d = device_copy(vals);
    Real four[1], one[1];
    deterministic_reduce_lanes<1, 0, 4>("test::reduce4", n, Squares{d}, four);
    deterministic_reduce_lanes<1, 0, 1>("test::reduce1", n, Squares{d}, one);
    EXPECT_TRUE(same_bits(four[0], one[0])) << n << " items";
  }
}

/// Segments side by side (a batch's specimens) give each the root it gets alone, to the bit: empty segments, one
/// item, a block, a block and one, and three levels beside one that ends at the first.
TEST(Reduce, SegmentsGiveEachTheBitsOfItsOwnReduction) {
  const std::vector<int> sizes = {0, 1, 3, kReduceBlock, kReduceBlock + 1, 5000, 0, kReduceBlock * kReduceBlock + 1, 7};
  std::vector<int> offsets = {0};
  for (int n : sizes) offsets.push_back(offsets.back() + n);
  const std::vector<double> all = awkward_values(offsets.back(), 11u);
  const ScalarView d = device_copy(all);
  std::vector<std::pair<int, int>> ranges;
  for (std::size_t s = 0; s < sizes.size(); ++s) ranges.emplace_back(offsets[s], offsets[s + 1]);
  SegmentedTree tree;
  tree.plan(ranges);
  EXPECT_EQ(tree.levels(), 3);
  const int S = static_cast<int>(sizes.size());
  Kokkos::View<Real*, MemSpace> roots("roots", 2 * S), lanes("lanes", S);
  Kokkos::deep_copy(roots, 5.0);  // every root must be written, the empty segments' too
  segmented_reduce_lanes_to<1, 1, 1>("test::segments", tree, OneAtATime<ValueAndMagnitude, 2>{{d}}, roots.data());
  segmented_reduce_lanes_to<1, 0, 4>("test::segments4", tree, Squares{d}, lanes.data());
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), roots);
  auto hl = Kokkos::create_mirror_view_and_copy(HostSpace(), lanes);
  for (int s = 0; s < S; ++s) {
    const std::vector<double> mine(all.begin() + offsets[s], all.begin() + offsets[s + 1]);
    const ScalarView ds = device_copy(mine.empty() ? std::vector<double>{0.0} : mine);
    Real alone[2], squares[1];
    deterministic_reduce<1, 1>("test::alone", sizes[s], ValueAndMagnitude{ds}, alone);
    deterministic_reduce_lanes<1, 0, 1>("test::alone1", sizes[s], Squares{ds}, squares);
    EXPECT_TRUE(same_bits(h(2 * s), alone[0])) << "segment " << s << " of " << sizes[s] << " items";
    EXPECT_TRUE(same_bits(h(2 * s + 1), alone[1])) << "segment " << s;
    EXPECT_TRUE(same_bits(hl(s), squares[0])) << "segment " << s << ", four lanes";
    EXPECT_TRUE(same_bits(h(2 * s), test::tree_sum(mine))) << "segment " << s;
  }
}

TEST(Reduce, ASegmentThatEndsBeforeItStartsIsRefused) {
  SegmentedTree tree;
  EXPECT_THROW(tree.plan({{0, 5}, {5, 3}}), std::invalid_argument);
  EXPECT_THROW(tree.plan({{-1, 3}}), std::invalid_argument);
}

}  // namespace
