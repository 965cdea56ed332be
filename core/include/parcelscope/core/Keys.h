#pragma once
// Stable keys: identities of parcels and blocks that depend neither on the
// order of features in the input nor on other features, so that overrides,
// session files, seeds and (later) edits find the same block again.
//
// A key is 64 bits, written as 16 lower-case hexadecimal digits. Hashes are
// FNV-1a (64 bit) and SplitMix64 mixing: fixed algorithms, so a key computed
// today is the key computed by any later build on any machine.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace parcelscope {

using Key = std::uint64_t;

/// FNV-1a of `bytes`, continuing from `basis` (the FNV offset basis by default).
Key hashBytes(std::string_view bytes, Key basis = 0xcbf29ce484222325ull);

/// SplitMix64 of `a` combined with `b`: a key derived from two keys or a key and an index.
Key mixKeys(Key a, Key b);

/// Key of part `part` of a multipart feature whose key is `feature`: the
/// feature's own key for part 0, so that a one-part feature keeps it.
Key partKey(Key feature, int part);

/// Key of a set of keys: independent of their order (they are sorted first)
/// and of anything else. An empty set gives 0.
Key setKey(std::vector<Key> keys);

/// 16 lower-case hexadecimal digits.
std::string keyText(Key key);

/// The key written by keyText; nullopt when `text` is not 16 hexadecimal digits.
std::optional<Key> parseKey(std::string_view text);

}  // namespace parcelscope
