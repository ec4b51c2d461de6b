#include "geomint/error.hpp"

#include <cmath>
#include <sstream>

#include "geomint/budget.hpp"
#include "geomint/text.hpp"

namespace geomint {

long step_count(double h, double T) {
  require_positive(h, "h");
  require_positive(T, "T");
  require(h <= T, "h = " + show(h) + " exceeds the horizon T = " + show(T));
  const double n = T / h;
  // Before the cast: T/h beyond a long is undefined behaviour (it gave negative step counts), beyond
  // max_steps_per_run it is work no run will finish.
  check_steps(n, "T/h = " + show(T) + "/" + show(h));
  const double N = std::round(n);
  if (std::abs(n - N) > 1e-9 * N) {
    std::ostringstream os;
    os << "T/h = " << n << " is not an integer: choose h that divides T = " << T;
    throw InputError(os.str());
  }
  return static_cast<long>(N);
}

}  // namespace geomint

namespace geomint {

namespace {

// The length of the valid UTF-8 sequence at text[i] (1..4), or 0 when it is not one (overlong forms, surrogates
// and code points above U+10FFFF included, as RFC 3629 defines them).
std::size_t utf8_length(std::string_view text, std::size_t i) {
  const auto at = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = at(i);
  if (c < 0x80) return 1;
  std::size_t len = 0;
  unsigned char lo = 0x80, hi = 0xbf;  // the range of the second byte
  if (c >= 0xc2 && c <= 0xdf) {
    len = 2;
  } else if (c >= 0xe0 && c <= 0xef) {
    len = 3;
    if (c == 0xe0) lo = 0xa0;
    if (c == 0xed) hi = 0x9f;
  } else if (c >= 0xf0 && c <= 0xf4) {
    len = 4;
    if (c == 0xf0) lo = 0x90;
    if (c == 0xf4) hi = 0x8f;
  } else {
    return 0;
  }
  if (i + len > text.size()) return 0;
  if (at(i + 1) < lo || at(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < len; ++k)
    if (at(i + k) < 0x80 || at(i + k) > 0xbf) return 0;
  return len;
}

// A C1 control: U+0080..U+009F, encoded C2 80..C2 9F (some terminals act on them as on ESC sequences).
bool c1_control(std::string_view text, std::size_t i, std::size_t len) {
  return len == 2 && static_cast<unsigned char>(text[i]) == 0xc2 && static_cast<unsigned char>(text[i + 1]) <= 0x9f;
}

bool control(unsigned char c) { return c < 0x20 || c == 0x7f; }

void hex(std::string& out, unsigned char c) {
  static const char digits[] = "0123456789abcdef";
  out += "\\x";
  out += digits[c >> 4];
  out += digits[c & 15];
}

}  // namespace

std::string one_line(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const std::size_t len = utf8_length(text, i);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (len == 0 || control(c)) {
      hex(out, c);
    } else if (c1_control(text, i, len)) {
      hex(out, c);
      hex(out, static_cast<unsigned char>(text[i + 1]));
      i += len;
      continue;
    } else {
      out.append(text.substr(i, len));
      i += len;
      continue;
    }
    ++i;
  }
  return out;
}

std::size_t first_unprintable(std::string_view text, std::string_view allowed) {
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const std::size_t len = utf8_length(text, i);
    if (len == 0 || c1_control(text, i, len)) return i;
    if (control(c) && allowed.find(static_cast<char>(c)) == std::string_view::npos) return i;
    i += len;
  }
  return std::string_view::npos;
}

}  // namespace geomint
