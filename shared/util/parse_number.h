#pragma once
// Numbers in text that users and other programs write: the whole text must be the number.

#include <charconv>
#include <string_view>
#include <system_error>

namespace silnet {

// True, with the number in `*out`, if all of `text` is one number of type T as
// std::from_chars reads it (no leading '+' or spaces, nothing after it, within T's range).
template <class T>
bool ParseWholeNumber(std::string_view text, T* out) {
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, *out);
  return error == std::errc() && stop == end;
}

}  // namespace silnet
