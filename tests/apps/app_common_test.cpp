// The apps' shared plumbing (apps/app_common.hpp) where it is more than a
// line: progress off a terminal (issue 58 item 3) and the validators'
// messages.
#include "app_common.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <thread>

#include "test_util.hpp"

namespace ta = touchdown::app;

namespace {

void sleep_ms(int ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); }

std::size_t count_lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

TEST(ProgressBar, OffATerminalLongWorkGetsAnEstimateThenPeriodicLines) {
  std::ostringstream out;
  // Scaled down: "long" is over 0.2 s, a line every 0.1 s, the estimate
  // after 0.02 s.
  ta::ProgressBar bar("app", "missions", false, out, ta::ProgressPacing{0.2, 0.1, 0.02});
  bar.draw(0, 40);
  for (std::size_t i = 1; i <= 40; ++i) {
    sleep_ms(10);
    bar.draw(i, 40);
  }
  bar.close();
  const std::string text = out.str();
  // The estimate after 0.02 s (two or three done): ~0.4 s for 40 missions.
  EXPECT_EQ(text.rfind("app: about ", 0), 0U) << text;
  EXPECT_NE(text.find(" for 40 missions (from the first "), std::string::npos) << text;
  // Then a line about every 0.1 s of the ~0.4 s, with the share done.
  EXPECT_NE(text.find(" missions ("), std::string::npos) << text;
  EXPECT_NE(text.find(" %), "), std::string::npos) << text;
  EXPECT_NE(text.find(" left\n"), std::string::npos) << text;
  EXPECT_GE(count_lines(text), 3U) << text;
  EXPECT_LE(count_lines(text), 8U) << text;
  // And the end.
  EXPECT_NE(text.find("app: 40 missions in "), std::string::npos) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos) << text;  // no bar in a log
}

TEST(ProgressBar, OffATerminalShortWorkPrintsNothing) {
  std::ostringstream out;
  ta::ProgressBar bar("app", "missions", false, out);  // a minute is long
  for (std::size_t i = 0; i <= 20; ++i) bar.draw(i, 20);
  bar.close();
  EXPECT_TRUE(out.str().empty()) << out.str();
}

TEST(ProgressBar, ResumedWorkEstimatesFromWhatThisRunDid) {
  std::ostringstream out;
  ta::ProgressBar bar("", "scenarios", false, out, ta::ProgressPacing{0.01, 10, 0.01});
  bar.draw(90, 100);  // 90 done by an earlier run
  sleep_ms(20);
  bar.draw(92, 100);
  // 2 in ~20 ms: ~80 ms for the 8 left, not 90/92 of the time.
  EXPECT_NE(out.str().find(" for 10 scenarios (from the first 2 in "), std::string::npos) << out.str();
}

TEST(Validators, AnAngleThatLooksLikeRadiansWarnsOnceParsed) {
  ta::parse_warnings().clear();
  std::string v = "3.14";
  EXPECT_EQ(ta::degrees_not_radians("--yaw-max")(v), "");  // taken as given
  v = "180";
  EXPECT_EQ(ta::degrees_not_radians("--yaw-max")(v), "");
  v = "0.5";
  EXPECT_EQ(ta::degrees_not_radians("--slope")(v), "");
  ASSERT_EQ(ta::parse_warnings().size(), 2U);
  EXPECT_EQ(ta::parse_warnings()[0],
            "--yaw-max 3.14 looks like radians (within +-2 pi, not a whole degree) but is read as degrees; if "
            "radians were meant, write 179.91");
  EXPECT_EQ(ta::parse_warnings()[1].rfind("--slope 0.5 looks like radians", 0), 0U);
  ta::parse_warnings().clear();
}

TEST(ProgressBar, OnATerminalABarWithTheDetail) {
  std::ostringstream out;
  ta::ProgressBar bar("app", "", true, out);
  bar.draw(0, 10, "generation 1/5");
  bar.draw(10, 10, "generation 5/5");
  EXPECT_EQ(out.str().rfind("\r[", 0), 0U) << out.str();
  EXPECT_NE(out.str().find("10/10  generation 5/5"), std::string::npos) << out.str();
  EXPECT_EQ(out.str().back(), '\n');
}

TEST(Validators, AMissingInputReadsAsTheLibrarySaysIt) {
  touchdown::test::TempDir dir;
  std::string missing = (dir / "m.yaml").string(), folder = dir.path().string();
  EXPECT_EQ(ta::existing_file()(missing), missing + ": cannot open: no such file");
  EXPECT_EQ(ta::existing_file()(folder), folder + ": cannot open: is a directory");
  EXPECT_EQ(ta::existing_directory()(missing), missing + ": cannot open: no such directory");
  EXPECT_EQ(ta::existing_directory()(folder), "");
  // Issue 58 item 4: an output's size is said when it is large.
  touchdown::test::write_text(dir / "big.stl", std::string(2'500'000, 'x'));
  EXPECT_EQ(ta::large_output_warning("--output", "out.stl", dir / "big.stl", "a hint", 1e6),
            "--output out.stl: 2.5 MB written; a hint");
  EXPECT_EQ(ta::large_output_warning("--output", "out.stl", dir / "big.stl", "a hint"), "");  // under 100 MB
  EXPECT_EQ(ta::duration_text(45), "45 s");
  EXPECT_EQ(ta::duration_text(600), "10 min");
  EXPECT_EQ(ta::duration_text(4.5 * 3600), "4.5 h");
  // Whole units from 10 up, never an exponent.
  EXPECT_EQ(ta::duration_text(99.6), "100 s");
  EXPECT_EQ(ta::duration_text(3.25), "3.2 s");
  EXPECT_EQ(ta::duration_text(7100), "118 min");
  EXPECT_EQ(ta::duration_text(200 * 3600.0), "200 h");
}
