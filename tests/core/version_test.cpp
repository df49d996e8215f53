#include "touchdown/touchdown.hpp"

#include <gtest/gtest.h>

TEST(Version, MatchesProjectVersion) { EXPECT_EQ(touchdown::version(), TOUCHDOWN_EXPECTED_VERSION); }
