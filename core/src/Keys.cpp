#include "parcelscope/core/Keys.h"

#include <algorithm>
#include <cstdio>

namespace parcelscope {

Key hashBytes(std::string_view bytes, Key basis) {
  Key h = basis;
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ull;
  }
  return h;
}

Key mixKeys(Key a, Key b) {
  Key x = a ^ (b + 0x9e3779b97f4a7c15ull + (a << 6) + (a >> 2));
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

Key partKey(Key feature, int part) { return part == 0 ? feature : mixKeys(feature, static_cast<Key>(part)); }

Key setKey(std::vector<Key> keys) {
  if (keys.empty()) return 0;
  std::sort(keys.begin(), keys.end());
  Key h = 0xcbf29ce484222325ull;
  for (const Key k : keys) h = mixKeys(h, k);
  return h;
}

std::string keyText(Key key) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(key));
  return text;
}

std::optional<Key> parseKey(std::string_view text) {
  if (text.size() != 16) return std::nullopt;
  Key key = 0;
  for (const char c : text) {
    int digit;
    if (c >= '0' && c <= '9') {
      digit = c - '0';
    } else if (c >= 'a' && c <= 'f') {
      digit = c - 'a' + 10;
    } else if (c >= 'A' && c <= 'F') {
      digit = c - 'A' + 10;
    } else {
      return std::nullopt;
    }
    key = key << 4 | static_cast<Key>(digit);
  }
  return key;
}

}  // namespace parcelscope
