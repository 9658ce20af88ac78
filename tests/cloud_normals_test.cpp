#include "focal/points/neighbours.h"

#include <gtest/gtest.h>

TEST(Neighbours, Placeholder) {}
