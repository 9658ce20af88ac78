#pragma once
// Internal: the argument checks that the neighbourhood queries (points/neighbours.cpp) and the
// tests on their lists (points/outlier_tests.cpp) share, one message each.

namespace focal::detail {

/// \throw InvalidInput ("neighbours: threads must be >= 0") when threads < 0.
void check_threads(int threads);

}  // namespace focal::detail
