// The point10 item decoders of LAZ (laz_items.h): POINT10, GPSTIME11, RGB12 and BYTE, versions 1 and 2,
// as the LASzip compressed format defines them. Version 1 predicts X and Y from the median of the last
// three differences; version 2 from a median of five kept per return context, Z from the last Z of the
// same return level, and codes which of the other fields changed as one symbol.
#include "io/laz_items.h"

#include <array>

namespace hsr::laz {

namespace {

/// The POINT10 fields as the record holds them (the first 20 bytes of formats 0-5).
struct Point10 {
  std::int32_t x = 0, y = 0, z = 0;
  std::uint16_t intensity = 0;
  std::uint8_t bit_byte = 0;        ///< return number (3 bits), number of returns (3), scan direction, edge
  std::uint8_t classification = 0;  ///< the whole byte 15 (class and the three flags)
  std::uint8_t scan_angle = 0;      ///< scan angle rank, as a byte
  std::uint8_t user_data = 0;
  std::uint16_t point_source = 0;

  explicit Point10(const unsigned char* r)
      : x(load_le<std::int32_t>(r)), y(load_le<std::int32_t>(r + 4)), z(load_le<std::int32_t>(r + 8)),
        intensity(load_le<std::uint16_t>(r + 12)), bit_byte(r[14]), classification(r[15]), scan_angle(r[16]),
        user_data(r[17]), point_source(load_le<std::uint16_t>(r + 18)) {}
  void store(unsigned char* r) const {
    store_le(r, x);
    store_le(r + 4, y);
    store_le(r + 8, z);
    store_le(r + 12, intensity);
    r[14] = bit_byte;
    r[15] = classification;
    r[16] = scan_angle;
    r[17] = user_data;
    store_le(r + 18, point_source);
  }
  unsigned return_number() const { return bit_byte & 7u; }
  unsigned number_of_returns() const { return (bit_byte >> 3) & 7u; }
  unsigned scan_direction() const { return (bit_byte >> 6) & 1u; }
};


// Context of X/Y (and intensity) by return number r and number of returns n (rows n, columns r): the
// well-formed pairs 1 <= r <= n <= 5 get contexts 0..14, the others are spread so that files numbering
// returns oddly still get separate contexts. Part of the format.
constexpr std::uint8_t kReturnMap[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8}, {14, 0, 1, 3, 6, 10, 10, 9},   {13, 1, 2, 4, 7, 11, 11, 10},
    {12, 3, 4, 5, 8, 12, 12, 11},   {11, 6, 7, 8, 9, 13, 13, 12},  {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};
/// Context of Z: how far the return is from the last one, |n - r|.
unsigned return_level(unsigned n, unsigned r) { return n > r ? n - r : r - n; }

// ---- POINT10 v1 -----------------------------------------------------------------------------------------

class Point10V1 final : public PointwiseItem {
 public:
  explicit Point10V1(const unsigned char* first) : last_(first) {}

  void decode(ArithmeticDecoder& dec, unsigned char* out) override {
    const std::int32_t median_x = median3(last_x_diff_), median_y = median3(last_y_diff_);
    const std::int32_t x_diff = dx_.decompress(dec, median_x, 0);
    last_.x = wrap_add(last_.x, x_diff);
    std::uint32_t k_bits = dx_.k();
    const std::int32_t y_diff = dy_.decompress(dec, median_y, k_bits < 19 ? k_bits : 19);
    last_.y = wrap_add(last_.y, y_diff);
    k_bits = (k_bits + dy_.k()) / 2;
    last_.z = dz_.decompress(dec, last_.z, k_bits < 19 ? k_bits : 19);
    const std::uint32_t changed = dec.decode_symbol(changed_values_);
    if (changed != 0) {
      if (changed & 32) last_.intensity = static_cast<std::uint16_t>(intensity_.decompress(dec, last_.intensity, 0));
      if (changed & 16) last_.bit_byte = static_cast<std::uint8_t>(dec.decode_symbol(bit_byte_[last_.bit_byte]));
      if (changed & 8)
        last_.classification = static_cast<std::uint8_t>(dec.decode_symbol(classification_[last_.classification]));
      if (changed & 4) last_.scan_angle = static_cast<std::uint8_t>(scan_angle_.decompress(dec, last_.scan_angle, k_bits < 3));
      if (changed & 2) last_.user_data = static_cast<std::uint8_t>(dec.decode_symbol(user_data_[last_.user_data]));
      if (changed & 1)
        last_.point_source = static_cast<std::uint16_t>(point_source_.decompress(dec, last_.point_source, 0));
    }
    last_x_diff_[last_incr_] = x_diff;
    last_y_diff_[last_incr_] = y_diff;
    last_incr_ = last_incr_ == 2 ? 0 : last_incr_ + 1;
    last_.store(out);
  }

 private:
  static std::int32_t median3(const std::array<std::int32_t, 3>& d) {
    if (d[0] < d[1]) return d[1] < d[2] ? d[1] : (d[0] < d[2] ? d[2] : d[0]);
    return d[0] < d[2] ? d[0] : (d[1] < d[2] ? d[2] : d[1]);
  }

  Point10 last_;
  std::array<std::int32_t, 3> last_x_diff_{}, last_y_diff_{};
  int last_incr_ = 0;
  IntegerDecompressor dx_{32, 1}, dy_{32, 20}, dz_{32, 20};
  IntegerDecompressor intensity_{16, 1}, scan_angle_{8, 2}, point_source_{16, 1};
  SymbolModel changed_values_{64};
  LazySymbolModels bit_byte_{256, 256}, classification_{256, 256}, user_data_{256, 256};
};

// ---- POINT10 v2 -----------------------------------------------------------------------------------------

class Point10V2 final : public PointwiseItem {
 public:
  explicit Point10V2(const unsigned char* first) : last_(first) { last_.intensity = 0; }

  void decode(ArithmeticDecoder& dec, unsigned char* out) override {
    const std::uint32_t changed = dec.decode_symbol(changed_values_);
    unsigned m, l, n;
    if (changed != 0) {
      if (changed & 32) last_.bit_byte = static_cast<std::uint8_t>(dec.decode_symbol(bit_byte_[last_.bit_byte]));
      n = last_.number_of_returns();
      const unsigned r = last_.return_number();
      m = kReturnMap[n][r];
      l = return_level(n, r);
      if (changed & 16) {
        last_.intensity = static_cast<std::uint16_t>(intensity_.decompress(dec, last_intensity_[m], m < 3 ? m : 3));
        last_intensity_[m] = last_.intensity;
      } else {
        last_.intensity = last_intensity_[m];
      }
      if (changed & 8)
        last_.classification = static_cast<std::uint8_t>(dec.decode_symbol(classification_[last_.classification]));
      if (changed & 4) {
        const std::uint32_t delta = dec.decode_symbol(scan_angle_[last_.scan_direction()]);
        last_.scan_angle = static_cast<std::uint8_t>(delta + last_.scan_angle);
      }
      if (changed & 2) last_.user_data = static_cast<std::uint8_t>(dec.decode_symbol(user_data_[last_.user_data]));
      if (changed & 1)
        last_.point_source = static_cast<std::uint16_t>(point_source_.decompress(dec, last_.point_source, 0));
    } else {
      n = last_.number_of_returns();
      const unsigned r = last_.return_number();
      m = kReturnMap[n][r];
      l = return_level(n, r);
    }
    const std::int32_t x_diff = dx_.decompress(dec, last_x_diff_[m].get(), n == 1);
    last_.x = wrap_add(last_.x, x_diff);
    last_x_diff_[m].add(x_diff);
    std::uint32_t k_bits = dx_.k();
    const std::int32_t y_diff = dy_.decompress(dec, last_y_diff_[m].get(), (n == 1) + (k_bits < 20 ? k_bits & ~1u : 20));
    last_.y = wrap_add(last_.y, y_diff);
    last_y_diff_[m].add(y_diff);
    k_bits = (dx_.k() + dy_.k()) / 2;
    last_.z = dz_.decompress(dec, last_height_[l], (n == 1) + (k_bits < 18 ? k_bits & ~1u : 18));
    last_height_[l] = last_.z;
    last_.store(out);
  }

 private:
  Point10 last_;
  std::array<std::uint16_t, 16> last_intensity_{};
  std::array<Median5, 16> last_x_diff_, last_y_diff_;
  std::array<std::int32_t, 8> last_height_{};
  IntegerDecompressor dx_{32, 2}, dy_{32, 22}, dz_{32, 20};
  IntegerDecompressor intensity_{16, 4}, point_source_{16, 1};
  SymbolModel changed_values_{64};
  std::array<SymbolModel, 2> scan_angle_{SymbolModel(256), SymbolModel(256)};
  LazySymbolModels bit_byte_{256, 256}, classification_{256, 256}, user_data_{256, 256};
};

// ---- GPSTIME11 v1 ---------------------------------------------------------------------------------------

class GpsTime11V1 final : public PointwiseItem {
 public:
  explicit GpsTime11V1(const unsigned char* first) : last_(load_le<std::uint64_t>(first)) {}

  void decode(ArithmeticDecoder& dec, unsigned char* out) override {
    constexpr std::uint32_t kMultiMax = 512;
    if (last_diff_ == 0) {
      const std::uint32_t multi = dec.decode_symbol(zero_diff_);
      if (multi == 1) {
        last_diff_ = gps_.decompress(dec, 0, 0);
        last_ += static_cast<std::uint64_t>(static_cast<std::int64_t>(last_diff_));
      } else if (multi == 2) {
        last_ = dec.read_int64();
      }
    } else {
      const std::uint32_t multi = dec.decode_symbol(multi_);
      if (multi < kMultiMax - 2) {
        std::int32_t diff;
        if (multi == 1) {
          diff = gps_.decompress(dec, last_diff_, 1);
          last_diff_ = diff;
          extreme_ = 0;
        } else if (multi == 0) {
          diff = gps_.decompress(dec, last_diff_ / 4, 2);
          if (++extreme_ > 3) {
            last_diff_ = diff;
            extreme_ = 0;
          }
        } else {
          const std::int32_t pred = wrap_mul(static_cast<std::int32_t>(multi), last_diff_);
          diff = gps_.decompress(dec, pred, multi < 10 ? 3 : (multi < 50 ? 4 : 5));
          if (multi == kMultiMax - 3 && ++extreme_ > 3) {
            last_diff_ = diff;
            extreme_ = 0;
          }
        }
        last_ += static_cast<std::uint64_t>(static_cast<std::int64_t>(diff));
      } else if (multi < kMultiMax - 1) {
        last_ = dec.read_int64();
      }
    }
    store_le(out, last_);
  }

 private:
  std::uint64_t last_;  ///< the double's bits, predicted as an integer
  std::int32_t last_diff_ = 0;
  int extreme_ = 0;
  SymbolModel multi_{512}, zero_diff_{3};
  IntegerDecompressor gps_{32, 6};
};

// ---- GPSTIME11 v2 ---------------------------------------------------------------------------------------

/// Four interleaved time sequences (multi-return and multi-channel data jump between a few time bases).
class GpsTime11V2 final : public PointwiseItem {
 public:
  explicit GpsTime11V2(const unsigned char* first) { time_[0] = load_le<std::uint64_t>(first); }

  void decode(ArithmeticDecoder& dec, unsigned char* out) override {
    constexpr std::uint32_t kMulti = 500, kUnchanged = 511, kCodeFull = 512;
    constexpr std::int32_t kMultiMinus = -10;
    // A switch to another sequence is followed by that sequence's own code: a loop, not recursion, so a
    // corrupt stream of switches cannot exhaust the stack.
    for (int guard = 0; guard < 64; ++guard) {
      if (diff_[last_] == 0) {
        const std::uint32_t multi = dec.decode_symbol(zero_diff_);
        if (multi == 1) {
          diff_[last_] = gps_.decompress(dec, 0, 0);
          time_[last_] += static_cast<std::uint64_t>(static_cast<std::int64_t>(diff_[last_]));
          extreme_[last_] = 0;
        } else if (multi == 2) {
          full_time(dec);
        } else if (multi > 2) {
          last_ = (last_ + multi - 2) & 3;
          continue;
        }
      } else {
        const std::uint32_t multi = dec.decode_symbol(multi_);
        if (multi == 1) {
          time_[last_] += static_cast<std::uint64_t>(static_cast<std::int64_t>(gps_.decompress(dec, diff_[last_], 1)));
          extreme_[last_] = 0;
        } else if (multi < kUnchanged) {
          std::int32_t diff;
          if (multi == 0) {
            diff = gps_.decompress(dec, 0, 7);
            count_extreme(diff);
          } else if (multi < kMulti) {
            diff = gps_.decompress(dec, wrap_mul(static_cast<std::int32_t>(multi), diff_[last_]), multi < 10 ? 2 : 3);
          } else if (multi == kMulti) {
            diff = gps_.decompress(dec, wrap_mul(kMulti, diff_[last_]), 4);
            count_extreme(diff);
          } else {
            const std::int32_t factor = static_cast<std::int32_t>(kMulti) - static_cast<std::int32_t>(multi);
            if (factor > kMultiMinus) {
              diff = gps_.decompress(dec, wrap_mul(factor, diff_[last_]), 5);
            } else {
              diff = gps_.decompress(dec, wrap_mul(kMultiMinus, diff_[last_]), 6);
              count_extreme(diff);
            }
          }
          time_[last_] += static_cast<std::uint64_t>(static_cast<std::int64_t>(diff));
        } else if (multi == kCodeFull) {
          full_time(dec);
        } else if (multi > kCodeFull) {
          last_ = (last_ + multi - kCodeFull) & 3;
          continue;
        }
      }
      break;
    }
    store_le(out, time_[last_]);
  }

 private:
  /// A time far from the current one: its high 32 bits predicted from the current, its low 32 raw; it
  /// starts a new sequence.
  void full_time(ArithmeticDecoder& dec) {
    next_ = (next_ + 1) & 3;
    const std::int32_t high = gps_.decompress(dec, static_cast<std::int32_t>(time_[last_] >> 32), 8);
    time_[next_] = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(high)) << 32) | dec.read_int();
    last_ = next_;
    diff_[last_] = 0;
    extreme_[last_] = 0;
  }
  /// After more than three extreme multipliers in a row, the extreme difference becomes the new step.
  void count_extreme(std::int32_t diff) {
    if (++extreme_[last_] > 3) {
      diff_[last_] = diff;
      extreme_[last_] = 0;
    }
  }

  std::uint32_t last_ = 0, next_ = 0;
  std::array<std::uint64_t, 4> time_{};
  std::array<std::int32_t, 4> diff_{}, extreme_{};
  SymbolModel multi_{516}, zero_diff_{6};
  IntegerDecompressor gps_{32, 9};
};

// ---- RGB12 v1 and v2 ------------------------------------------------------------------------------------

class Rgb12V1 final : public PointwiseItem {
 public:
  explicit Rgb12V1(const unsigned char* first) : last_(Rgb16::load(first)) {}

  void decode(ArithmeticDecoder& dec, unsigned char* out) override {
    const std::uint32_t used = dec.decode_symbol(byte_used_);
    Rgb16 now;
    for (std::uint32_t i = 0; i < 3; ++i) {  // low then high byte, each predicted by the same byte of the last colour
      const unsigned lo = last_.c[i] & 0xFFu, hi = last_.c[i] >> 8u;
      const unsigned new_lo = (used & (1u << (2 * i))) ? static_cast<std::uint8_t>(rgb_.decompress(dec, lo, 2 * i)) : lo;
      const unsigned new_hi =
          (used & (1u << (2 * i + 1))) ? static_cast<std::uint8_t>(rgb_.decompress(dec, hi, 2 * i + 1)) : hi;
      now.c[i] = static_cast<std::uint16_t>(new_lo | (new_hi << 8));
    }
    last_ = now;
    now.store(out);
  }

 private:
  Rgb16 last_;
  SymbolModel byte_used_{64};
  IntegerDecompressor rgb_{8, 6};
};

class Rgb12V2 final : public PointwiseItem {
 public:
  explicit Rgb12V2(const unsigned char* first) : last_(Rgb16::load(first)) {}
  void decode(ArithmeticDecoder& dec, unsigned char* out) override {
    last_ = decode_rgb_v2(dec, models_, last_);
    last_.store(out);
  }

 private:
  Rgb16 last_;
  RgbCoder models_;
};

// ---- BYTE v1 and v2 -------------------------------------------------------------------------------------

class ByteV1 final : public PointwiseItem {
 public:
  ByteV1(const unsigned char* first, std::size_t n) : last_(first, first + n), ic_(8, static_cast<std::uint32_t>(n)) {}
  void decode(ArithmeticDecoder& dec, unsigned char* out) override {
    for (std::size_t i = 0; i < last_.size(); ++i)
      out[i] = last_[i] = static_cast<std::uint8_t>(ic_.decompress(dec, last_[i], static_cast<std::uint32_t>(i)));
  }

 private:
  std::vector<std::uint8_t> last_;
  IntegerDecompressor ic_;
};

class ByteV2 final : public PointwiseItem {
 public:
  ByteV2(const unsigned char* first, std::size_t n) : last_(first, first + n) {
    models_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) models_.emplace_back(256);
  }
  void decode(ArithmeticDecoder& dec, unsigned char* out) override {
    for (std::size_t i = 0; i < last_.size(); ++i)
      out[i] = last_[i] = fold_u8(last_[i] + static_cast<int>(dec.decode_symbol(models_[i])));
  }

 private:
  std::vector<std::uint8_t> last_;
  std::vector<SymbolModel> models_;
};

}  // namespace

Rgb16 decode_rgb_v2(ArithmeticDecoder& dec, RgbCoder& m, const Rgb16& last) {
  const std::uint32_t sym = dec.decode_symbol(m.byte_used);
  const auto corr = [&](int i) { return static_cast<int>(dec.decode_symbol(m.diff[i])); };
  Rgb16 now;
  const int last_lo[3] = {last.c[0] & 0xFF, last.c[1] & 0xFF, last.c[2] & 0xFF};
  const int last_hi[3] = {last.c[0] >> 8, last.c[1] >> 8, last.c[2] >> 8};
  const int r_lo = (sym & 1) ? fold_u8(corr(0) + last_lo[0]) : last_lo[0];
  const int r_hi = (sym & 2) ? fold_u8(corr(1) + last_hi[0]) : last_hi[0];
  now.c[0] = static_cast<std::uint16_t>(r_lo | (r_hi << 8));
  if (sym & 64) {
    int diff = r_lo - last_lo[0];
    const int g_lo = (sym & 4) ? fold_u8(corr(2) + clamp_u8(diff + last_lo[1])) : last_lo[1];
    int b_lo = last_lo[2];
    if (sym & 16) {
      const int c = corr(4);
      diff = (diff + (g_lo - last_lo[1])) / 2;
      b_lo = fold_u8(c + clamp_u8(diff + last_lo[2]));
    }
    diff = r_hi - last_hi[0];
    const int g_hi = (sym & 8) ? fold_u8(corr(3) + clamp_u8(diff + last_hi[1])) : last_hi[1];
    int b_hi = last_hi[2];
    if (sym & 32) {
      const int c = corr(5);
      diff = (diff + (g_hi - last_hi[1])) / 2;
      b_hi = fold_u8(c + clamp_u8(diff + last_hi[2]));
    }
    now.c[1] = static_cast<std::uint16_t>(g_lo | (g_hi << 8));
    now.c[2] = static_cast<std::uint16_t>(b_lo | (b_hi << 8));
  } else {
    now.c[1] = now.c[2] = now.c[0];
  }
  return now;
}

std::string item_name(const Item& item) {
  std::string name;
  switch (item.type) {
    case kByte: name = "BYTE"; break;
    case kPoint10: name = "POINT10"; break;
    case kGpsTime11: name = "GPSTIME11"; break;
    case kRgb12: name = "RGB12"; break;
    case kWavePacket13: name = "WAVEPACKET13"; break;
    case kPoint14: name = "POINT14"; break;
    case kRgb14: name = "RGB14"; break;
    case kRgbNir14: name = "RGBNIR14"; break;
    case kWavePacket14: name = "WAVEPACKET14"; break;
    case kByte14: name = "BYTE14"; break;
    default: name = "item type " + std::to_string(item.type);
  }
  return name + " v" + std::to_string(item.version);
}

std::unique_ptr<PointwiseItem> make_pointwise_item(const Item& item, const unsigned char* first) {
  const bool v1 = item.version == 1, v2 = item.version == 2;
  switch (item.type) {
    case kPoint10:
      if (item.size != 20) return nullptr;
      if (v1) return std::make_unique<Point10V1>(first);
      if (v2) return std::make_unique<Point10V2>(first);
      break;
    case kGpsTime11:
      if (item.size != 8) return nullptr;
      if (v1) return std::make_unique<GpsTime11V1>(first);
      if (v2) return std::make_unique<GpsTime11V2>(first);
      break;
    case kRgb12:
      if (item.size != 6) return nullptr;
      if (v1) return std::make_unique<Rgb12V1>(first);
      if (v2) return std::make_unique<Rgb12V2>(first);
      break;
    case kByte:
      if (item.size == 0) return nullptr;
      if (v1) return std::make_unique<ByteV1>(first, item.size);
      if (v2) return std::make_unique<ByteV2>(first, item.size);
      break;
    default: break;
  }
  return nullptr;
}

}  // namespace hsr::laz
