#pragma once
// Number text, private to the library and its apps (not installed): the one
// place that decides how a double is printed. Four styles cover every
// message, table, file and figure; pick by what the reader needs:
//
//   format_exact(v)          round trip: files read back to the same bits
//                            ("0.1", "1e+21", "-0", "nan", "inf");
//   format_general(v, sig)   messages: printf's %.<sig>g, what `ostream << v`
//                            prints at its default precision 6 ("0.25",
//                            "1e-07", "1e+21", "3.14159");
//   format_fixed(v, dec)     tables and CSV columns: printf's %.<dec>f to the
//                            byte ("2.50", "-0.00" for -0.001);
//   format_trimmed(v, dec)   figures and short labels: %.<dec>f without
//                            trailing zeros ("1.5", "2", "0.25").
//
// Negative zero: format_exact keeps its sign (it is part of the value and
// the file must read back to it); format_general and format_trimmed never
// print a signed zero ("0", also for a negative value that rounds to zero);
// format_fixed prints what printf prints ("-0.000"), because the tables and
// CSV files the apps write print it so today. A caller that wants a plain 0
// from format_fixed passes `v + 0.0` (which turns -0.0 into 0.0).
//
// NaN and infinities print as printf and std::to_chars print them ("nan",
// "-nan", "inf", "-inf"). Nothing here depends on the global locale.
#include <string>
#include <string_view>

namespace touchdown::detail {

/// Shortest decimal text that reads back to exactly `v` (std::to_chars).
std::string format_exact(double v);

/// Shortest decimal text that reads back to exactly `v`, written into `buf`
/// (no allocation: the point-cloud writers call it per coordinate).
std::string_view format_exact(float v, char (&buf)[32]);

/// printf's "%.<significant>g" (`ostream << v` at precision `significant`);
/// -0.0 prints as "0". `significant` in [1, 17].
std::string format_general(double v, int significant = 6);

/// printf's "%.<decimals>f", sign of a zero included. `decimals` in [0, 17].
std::string format_fixed(double v, int decimals);

/// A count and its noun for messages: "1 segment", "0 segments",
/// "3 segments" (the plural adds "s"; `plural` overrides it).
std::string count_noun(long long n, std::string_view noun, std::string_view plural = {});

/// "%.<decimals>f" without trailing zeros and without a trailing point;
/// a value that prints as zero prints "0" (never "-0"). `decimals` in [0, 17].
std::string format_trimmed(double v, int decimals);

}  // namespace touchdown::detail
