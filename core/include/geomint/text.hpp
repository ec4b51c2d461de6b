#pragma once
// Text from outside (a path, a formula from someone else's file) made safe to show, and found unsafe to read.
// Defined in error.cpp, beside the errors whose messages it guards.
#include <cstddef>
#include <string>
#include <string_view>

namespace geomint {

// Text as one printable line, whatever it quotes: \n \r \t written as those escapes, every other control byte (C0,
// DEL, the C1 controls U+0080..U+009F) and every byte that is not part of valid UTF-8 as \xNN. A terminal then never
// acts on a message (an ESC sequence retitles or recolours it, \r overwrites it), a NUL does not cut it short, and
// Python can decode it. Valid UTF-8 (a degree sign) stays as it is.
std::string one_line(std::string_view text);

// The offset of the first byte of `text` that is a control byte (C0 other than those in `allowed`, DEL, a C1
// control) or does not begin valid UTF-8; std::string_view::npos when there is none. For readers that refuse such
// text with its place.
std::size_t first_unprintable(std::string_view text, std::string_view allowed = "");

}  // namespace geomint
