#include <gtest/gtest.h>

#include "touchdown/touchdown.hpp"

TEST(Version, MatchesProjectVersion) { EXPECT_EQ(touchdown::version(), TOUCHDOWN_EXPECTED_VERSION); }
