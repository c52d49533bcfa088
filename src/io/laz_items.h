// The item decoders of the LASzip compressed format: each turns the compressed stream back into one part of
// the LAS point record (the items of a file, in order, make up the whole record).
//   point10 family (compressors 1 and 2, point formats 0-5): POINT10 (the 20 bytes every legacy format
//     starts with), GPSTIME11 (8), RGB12 (6), BYTE (extra bytes), versions 1 and 2; all items of a chunk
//     share one arithmetic decoder, and the first point of a chunk is stored raw (laz_items10.cpp).
//   point14 family (compressor 3, "layered", point formats 6-10): POINT14 (30 bytes), RGB14 (6),
//     RGBNIR14 (8), BYTE14, version 3; each field group is its own layer with its own decoder, and up to
//     four scanner channels keep separate contexts (laz_items14.cpp).
// Decoders keep the previous point (the prediction) and their models; a new chunk gets new decoders.
#pragma once

#include "io/laz_arithmetic.h"

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace hsr::laz {

/// Item types of the LASzip VLR.
enum ItemType : std::uint16_t {
  kByte = 0,
  kPoint10 = 6,
  kGpsTime11 = 7,
  kRgb12 = 8,
  kWavePacket13 = 9,
  kPoint14 = 10,
  kRgb14 = 11,
  kRgbNir14 = 12,
  kWavePacket14 = 13,
  kByte14 = 14,
};

struct Item {
  std::uint16_t type = 0, size = 0, version = 0;
};

/// "POINT10 v2" etc., for messages.
std::string item_name(const Item& item);

/// Little-endian loads and stores of the record fields, whatever the host's byte order.
template <class T>
T load_le(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  if constexpr (std::endian::native == std::endian::big && sizeof(T) > 1) {
    auto b = std::bit_cast<std::array<unsigned char, sizeof(T)>>(v);
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    v = std::bit_cast<T>(b);
  }
  return v;
}
template <class T>
void store_le(unsigned char* p, T v) {
  if constexpr (std::endian::native == std::endian::big && sizeof(T) > 1) {
    auto b = std::bit_cast<std::array<unsigned char, sizeof(T)>>(v);
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    v = std::bit_cast<T>(b);
  }
  std::memcpy(p, &v, sizeof(T));
}

/// Wrapping int32 arithmetic (the format's integers wrap; signed overflow must not be undefined here).
inline std::int32_t wrap_add(std::int32_t a, std::int32_t b) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) + static_cast<std::uint32_t>(b));
}
inline std::int32_t wrap_mul(std::int32_t a, std::int32_t b) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) * static_cast<std::uint32_t>(b));
}
/// Byte arithmetic of the RGB and BYTE items: wrap into [0, 255] (U8_FOLD) and clamp (U8_CLAMP).
inline std::uint8_t fold_u8(int v) { return static_cast<std::uint8_t>(v); }
inline int clamp_u8(int v) { return v < 0 ? 0 : (v > 255 ? 255 : v); }

/// A colour as RGB12 / RGB14 store it: red, green, blue, 16 bits each, little-endian.
struct Rgb16 {
  std::uint16_t c[3] = {0, 0, 0};
  static Rgb16 load(const unsigned char* p) {
    Rgb16 v;
    for (int i = 0; i < 3; ++i) v.c[i] = load_le<std::uint16_t>(p + 2 * i);
    return v;
  }
  void store(unsigned char* p) const {
    for (int i = 0; i < 3; ++i) store_le(p + 2 * i, c[i]);
  }
};

/// The colour coder of RGB12 v2 and RGB14 v3: which of the six bytes changed (and whether green and blue
/// differ from red) as one symbol; red's bytes against the last red, green's and blue's against the last
/// values moved by red's (and green's) change.
struct RgbCoder {
  SymbolModel byte_used{128};
  std::array<SymbolModel, 6> diff{SymbolModel(256), SymbolModel(256), SymbolModel(256),
                                  SymbolModel(256), SymbolModel(256), SymbolModel(256)};
};
Rgb16 decode_rgb_v2(ArithmeticDecoder& dec, RgbCoder& coder, const Rgb16& last);

// ---- point10 family ------------------------------------------------------------------------------------

/// One item of a pointwise chunk. Constructed from the chunk's raw first point (this item's bytes);
/// decode() writes the next point's bytes of this item.
class PointwiseItem {
 public:
  virtual ~PointwiseItem() = default;
  virtual void decode(ArithmeticDecoder& dec, unsigned char* out) = 0;
};

/// The decoder of `item` (its raw first value at `first`), or null when its type/version is unknown.
std::unique_ptr<PointwiseItem> make_pointwise_item(const Item& item, const unsigned char* first);

// ---- point14 family ------------------------------------------------------------------------------------

/// A byte range of a layer (empty: the field does not change within the chunk).
struct Layer {
  const unsigned char* begin = nullptr;
  const unsigned char* end = nullptr;
  bool empty() const { return begin == end; }
};

/// One item of a layered chunk. The POINT14 item decides the scanner channel (`context`) that the other
/// items of the same point follow.
class LayeredItem {
 public:
  virtual ~LayeredItem() = default;
  /// How many layer sizes this item stores in the chunk head.
  virtual std::size_t layer_count() const = 0;
  /// Begins a chunk: the raw first point's bytes of this item, this item's layers, the first context.
  virtual void start(const unsigned char* first, const std::vector<Layer>& layers, int context) = 0;
  /// Decodes the next point's bytes of this item. The caller passes context 0 for each point; POINT14
  /// sets it to the new channel on a point that switches channels, and the items after it follow it.
  virtual void decode(unsigned char* out, int& context) = 0;
  /// Zero bytes its decoders were fed past the ends of their layers.
  virtual std::uint32_t overrun() const = 0;
};

/// The decoder of `item`, or null when its type/version is unknown.
std::unique_ptr<LayeredItem> make_layered_item(const Item& item);

/// The scanner channel of a raw POINT14 record (bits 4-5 of byte 15).
inline int scanner_channel(const unsigned char* point14) { return (point14[15] >> 4) & 3; }

}  // namespace hsr::laz
