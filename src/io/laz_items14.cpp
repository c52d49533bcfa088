// The point14 item decoders of LAZ (laz_items.h): POINT14, RGB14, RGBNIR14 and BYTE14, version 3 (the
// "layered" compressor of LAS 1.4 point formats 6-10), as the LASzip compressed format defines them. Each
// group of fields is its own layer (own bytes, own arithmetic decoder), so a layer whose field never changes
// within a chunk is empty and costs nothing. Each scanner channel (0-3) has its own context: models and
// predictions; a context first used mid-chunk starts from the point before.
#include "io/laz_items.h"

#include <array>

namespace hsr::laz {

namespace {

/// The POINT14 fields as the record of formats 6-10 holds them (its first 30 bytes).
struct Point14 {
  std::int32_t x = 0, y = 0, z = 0;
  std::uint16_t intensity = 0;
  std::uint8_t return_number = 0, number_of_returns = 0;  ///< 4 bits each (byte 14)
  std::uint8_t class_flags = 0, channel = 0, scan_direction = 0, edge = 0;  ///< byte 15: 4, 2, 1, 1 bits
  std::uint8_t classification = 0, user_data = 0;
  std::int16_t scan_angle = 0;
  std::uint16_t point_source = 0;
  std::uint64_t gps_time = 0;  ///< the double's bits

  static Point14 load(const unsigned char* r) {
    Point14 p;
    p.x = load_le<std::int32_t>(r);
    p.y = load_le<std::int32_t>(r + 4);
    p.z = load_le<std::int32_t>(r + 8);
    p.intensity = load_le<std::uint16_t>(r + 12);
    p.return_number = r[14] & 0x0F;
    p.number_of_returns = r[14] >> 4;
    p.class_flags = r[15] & 0x0F;
    p.channel = (r[15] >> 4) & 3;
    p.scan_direction = (r[15] >> 6) & 1;
    p.edge = r[15] >> 7;
    p.classification = r[16];
    p.user_data = r[17];
    p.scan_angle = load_le<std::int16_t>(r + 18);
    p.point_source = load_le<std::uint16_t>(r + 20);
    p.gps_time = load_le<std::uint64_t>(r + 22);
    return p;
  }
  void store(unsigned char* r) const {
    store_le(r, x);
    store_le(r + 4, y);
    store_le(r + 8, z);
    store_le(r + 12, intensity);
    r[14] = static_cast<unsigned char>(return_number | (number_of_returns << 4));
    r[15] = static_cast<unsigned char>(class_flags | (channel << 4) | (scan_direction << 6) | (edge << 7));
    r[16] = classification;
    r[17] = user_data;
    store_le(r + 18, scan_angle);
    store_le(r + 20, point_source);
    store_le(r + 22, gps_time);
  }
};

// Context of X/Y by number of returns n (rows) and return number r (columns), 6 classes: single,
// first, last, intermediate, and odd pairs. Part of the format.
constexpr std::uint8_t kReturnMap6[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};
/// Context of Z: |n - r| capped at 7.
unsigned return_level8(unsigned n, unsigned r) {
  const unsigned d = n > r ? n - r : r - n;
  return d < 7 ? d : 7;
}


/// A layer's decoder, started only when the layer has bytes.
struct LayerDecoder {
  ArithmeticDecoder dec;
  bool present = false;
  void start(const Layer& layer) {
    present = !layer.empty();
    if (present) dec.start(layer.begin, layer.end);
  }
  std::uint32_t overrun() const { return present ? dec.overrun() : 0; }
};

// ---- POINT14 v3 -----------------------------------------------------------------------------------------

class Point14V3 final : public LayeredItem {
 public:
  std::size_t layer_count() const override { return kLayers; }

  void start(const unsigned char* first, const std::vector<Layer>& layers, int) override {
    for (std::size_t i = 0; i < kLayers; ++i) layer_[i].start(layers[i]);
    xy_layer_ = layers[0];
    xy_started_ = false;
    for (auto& c : channel_) c.reset();
    const Point14 p = Point14::load(first);
    current_ = p.channel;
    open_channel(current_, p);
  }

  void decode(unsigned char* out, int& context) override {
    if (!xy_started_) {  // started on first use: a one-point chunk may have no XY bytes at all
      layer_[0].present = true;
      layer_[0].dec.start(xy_layer_.begin, xy_layer_.end);
      xy_started_ = true;
    }
    ArithmeticDecoder& xy = layer_[0].dec;
    Channel* c = channel_[current_].get();
    const unsigned lpr = (c->last.return_number == 1) | ((c->last.return_number >= c->last.number_of_returns) << 1) |
                         (c->gps_time_change << 2);
    const std::uint32_t changed = xy.decode_symbol(c->changed_values[lpr]);
    if (changed & 64) {  // another scanner channel
      const unsigned channel = (current_ + xy.decode_symbol(c->scanner_channel) + 1) % 4;
      if (!channel_[channel]) open_channel(channel, c->last);
      current_ = channel;
      c = channel_[channel].get();
      c->last.channel = static_cast<std::uint8_t>(channel);
      // Version 3 hands the channel on to the other items only on a point that changes it; on the others
      // they get the caller's 0 (LASzip's reader and laz-perf alike; version 4 passes it on every point).
      context = static_cast<int>(channel);
    }
    const bool point_source_change = changed & 32, gps_change = changed & 16, scan_angle_change = changed & 8;
    Point14& last = c->last;
    const unsigned last_n = last.number_of_returns, last_r = last.return_number;
    const unsigned n = (changed & 4) ? xy.decode_symbol(c->number_of_returns[last_n]) : last_n;
    unsigned r = last_r;
    switch (changed & 3) {
      case 1: r = (last_r + 1) % 16; break;
      case 2: r = (last_r + 15) % 16; break;
      case 3:
        if (gps_change) r = xy.decode_symbol(c->return_number[last_r]);
        else r = (last_r + xy.decode_symbol(c->return_number_gps_same) + 2) % 16;
        break;
      default: break;
    }
    last.number_of_returns = static_cast<std::uint8_t>(n);
    last.return_number = static_cast<std::uint8_t>(r);
    const unsigned m = kReturnMap6[n][r], l = return_level8(n, r);
    const unsigned cpr = (r == 1 ? 2u : 0u) + (r >= n ? 1u : 0u);  // first, last
    const unsigned xy_ctx = (m << 1) | gps_change;

    const std::int32_t dx = c->dx.decompress(xy, c->last_x_diff[xy_ctx].get(), n == 1);
    last.x = wrap_add(last.x, dx);
    c->last_x_diff[xy_ctx].add(dx);
    std::uint32_t k_bits = c->dx.k();
    const std::int32_t dy = c->dy.decompress(xy, c->last_y_diff[xy_ctx].get(), (n == 1) + (k_bits < 20 ? k_bits & ~1u : 20));
    last.y = wrap_add(last.y, dy);
    c->last_y_diff[xy_ctx].add(dy);
    if (layer_[kZ].present) {
      k_bits = (c->dx.k() + c->dy.k()) / 2;
      last.z = c->dz.decompress(layer_[kZ].dec, c->last_z[l], (n == 1) + (k_bits < 18 ? k_bits & ~1u : 18));
      c->last_z[l] = last.z;
    }
    if (layer_[kClassification].present) {
      const unsigned ctx = ((last.classification & 0x1Fu) << 1) + (cpr == 3 ? 1u : 0u);
      last.classification = static_cast<std::uint8_t>(layer_[kClassification].dec.decode_symbol(c->classification[ctx]));
    }
    if (layer_[kFlags].present) {
      const unsigned ctx = (last.edge << 5) | (last.scan_direction << 4) | last.class_flags;
      const std::uint32_t flags = layer_[kFlags].dec.decode_symbol(c->flags[ctx]);
      last.edge = (flags >> 5) & 1;
      last.scan_direction = (flags >> 4) & 1;
      last.class_flags = flags & 0x0F;
    }
    if (layer_[kIntensity].present) {
      const unsigned ctx = (cpr << 1) | gps_change;
      last.intensity = static_cast<std::uint16_t>(c->intensity.decompress(layer_[kIntensity].dec, c->last_intensity[ctx], cpr));
      c->last_intensity[ctx] = last.intensity;
    }
    if (layer_[kScanAngle].present && scan_angle_change)
      last.scan_angle = static_cast<std::int16_t>(c->scan_angle.decompress(layer_[kScanAngle].dec, last.scan_angle, gps_change));
    if (layer_[kUserData].present)
      last.user_data = static_cast<std::uint8_t>(layer_[kUserData].dec.decode_symbol(c->user_data[last.user_data / 4]));
    if (layer_[kPointSource].present && point_source_change)
      last.point_source = static_cast<std::uint16_t>(c->point_source.decompress(layer_[kPointSource].dec, last.point_source, 0));
    if (layer_[kGpsTime].present && gps_change) {
      read_gps_time(*c, layer_[kGpsTime].dec);
      last.gps_time = c->gps_time[c->gps_last];
    }
    last.store(out);
    c->gps_time_change = gps_change;
  }

  std::uint32_t overrun() const override {
    std::uint32_t total = 0;
    for (const auto& l : layer_) total += l.overrun();
    return total;
  }

 private:
  enum : std::size_t { kXY, kZ, kClassification, kFlags, kIntensity, kScanAngle, kUserData, kPointSource, kGpsTime, kLayers };

  /// Models and predictions of one scanner channel.
  struct Channel {
    Point14 last;
    bool gps_time_change = false;
    std::array<SymbolModel, 8> changed_values{SymbolModel(128), SymbolModel(128), SymbolModel(128), SymbolModel(128),
                                              SymbolModel(128), SymbolModel(128), SymbolModel(128), SymbolModel(128)};
    SymbolModel scanner_channel{3};
    LazySymbolModels number_of_returns{16, 16}, return_number{16, 16};
    SymbolModel return_number_gps_same{13};
    IntegerDecompressor dx{32, 2}, dy{32, 22}, dz{32, 20};
    LazySymbolModels classification{64, 256}, flags{64, 64}, user_data{64, 256};
    IntegerDecompressor intensity{16, 4}, scan_angle{16, 2}, point_source{16, 1};
    SymbolModel gps_multi{515}, gps_zero_diff{5};
    IntegerDecompressor gps{32, 9};
    std::array<Median5, 12> last_x_diff, last_y_diff;
    std::array<std::int32_t, 8> last_z{};
    std::array<std::uint16_t, 8> last_intensity{};
    std::uint32_t gps_last = 0, gps_next = 0;
    std::array<std::uint64_t, 4> gps_time{};
    std::array<std::int32_t, 4> gps_diff{}, gps_extreme{};
  };

  void open_channel(unsigned index, const Point14& from) {
    auto c = std::make_unique<Channel>();
    c->last = from;
    c->last_z.fill(from.z);
    c->last_intensity.fill(from.intensity);
    c->gps_time[0] = from.gps_time;
    channel_[index] = std::move(c);
  }

  /// GPS time: four sequences per channel, as in GPSTIME11 v2 with the "unchanged" code dropped (the
  /// changed-values symbol says whether the time changed).
  static void read_gps_time(Channel& c, ArithmeticDecoder& dec) {
    constexpr std::uint32_t kMulti = 500, kCodeFull = 511;
    constexpr std::int32_t kMultiMinus = -10;
    const auto extreme = [&c](std::int32_t diff) {
      if (++c.gps_extreme[c.gps_last] > 3) {
        c.gps_diff[c.gps_last] = diff;
        c.gps_extreme[c.gps_last] = 0;
      }
    };
    const auto full = [&c, &dec] {
      c.gps_next = (c.gps_next + 1) & 3;
      const std::int32_t high = c.gps.decompress(dec, static_cast<std::int32_t>(c.gps_time[c.gps_last] >> 32), 8);
      c.gps_time[c.gps_next] = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(high)) << 32) | dec.read_int();
      c.gps_last = c.gps_next;
      c.gps_diff[c.gps_last] = 0;
      c.gps_extreme[c.gps_last] = 0;
    };
    for (int guard = 0; guard < 64; ++guard) {  // a sequence switch is followed by that sequence's code
      std::uint32_t& last = c.gps_last;
      if (c.gps_diff[last] == 0) {
        const std::uint32_t multi = dec.decode_symbol(c.gps_zero_diff);
        if (multi == 0) {
          c.gps_diff[last] = c.gps.decompress(dec, 0, 0);
          c.gps_time[last] += static_cast<std::uint64_t>(static_cast<std::int64_t>(c.gps_diff[last]));
          c.gps_extreme[last] = 0;
        } else if (multi == 1) {
          full();
        } else {
          last = (last + multi - 1) & 3;
          continue;
        }
      } else {
        const std::uint32_t multi = dec.decode_symbol(c.gps_multi);
        if (multi == 1) {
          c.gps_time[last] += static_cast<std::uint64_t>(static_cast<std::int64_t>(c.gps.decompress(dec, c.gps_diff[last], 1)));
          c.gps_extreme[last] = 0;
        } else if (multi < kCodeFull) {
          std::int32_t diff;
          if (multi == 0) {
            diff = c.gps.decompress(dec, 0, 7);
            extreme(diff);
          } else if (multi < kMulti) {
            diff = c.gps.decompress(dec, wrap_mul(static_cast<std::int32_t>(multi), c.gps_diff[last]), multi < 10 ? 2 : 3);
          } else if (multi == kMulti) {
            diff = c.gps.decompress(dec, wrap_mul(kMulti, c.gps_diff[last]), 4);
            extreme(diff);
          } else {
            const std::int32_t factor = static_cast<std::int32_t>(kMulti) - static_cast<std::int32_t>(multi);
            if (factor > kMultiMinus) {
              diff = c.gps.decompress(dec, wrap_mul(factor, c.gps_diff[last]), 5);
            } else {
              diff = c.gps.decompress(dec, wrap_mul(kMultiMinus, c.gps_diff[last]), 6);
              extreme(diff);
            }
          }
          c.gps_time[last] += static_cast<std::uint64_t>(static_cast<std::int64_t>(diff));
        } else if (multi == kCodeFull) {
          full();
        } else {
          last = (last + multi - kCodeFull) & 3;
          continue;
        }
      }
      return;
    }
  }

  std::array<LayerDecoder, kLayers> layer_;
  Layer xy_layer_;
  bool xy_started_ = false;
  std::array<std::unique_ptr<Channel>, 4> channel_;
  unsigned current_ = 0;
};

// ---- RGB14, RGBNIR14 and BYTE14 v3 ----------------------------------------------------------------------

/// Follows the channel POINT14 chose. As LASzip does, a switch to a channel already seen keeps predicting
/// from the previous channel's last value (and updates that one); only a new channel copies it.
template <class Context>
class ChannelFollower {
 public:
  void reset(int context, Context fresh) {
    for (auto& c : channel_) c.reset();
    current_ = context & 3;
    channel_[current_] = std::make_unique<Context>(std::move(fresh));
    last_ = channel_[current_].get();
  }
  /// The context whose models decode this point, and (via last()) the one whose value predicts it.
  Context& follow(int context) {
    Context* last = channel_[current_].get();
    if (static_cast<unsigned>(context & 3) != current_) {
      current_ = context & 3;
      if (!channel_[current_]) {
        channel_[current_] = std::make_unique<Context>(last->fresh_copy());
        last = channel_[current_].get();
      }
    }
    last_ = last;
    return *channel_[current_];
  }
  Context& last() { return *last_; }

 private:
  std::array<std::unique_ptr<Context>, 4> channel_;
  unsigned current_ = 0;
  Context* last_ = nullptr;
};

class Rgb14V3 final : public LayeredItem {
 public:
  explicit Rgb14V3(bool nir) : nir_(nir) {}
  std::size_t layer_count() const override { return nir_ ? 2 : 1; }

  void start(const unsigned char* first, const std::vector<Layer>& layers, int context) override {
    rgb_.start(layers[0]);
    if (nir_) nir_layer_.start(layers[1]);
    Context fresh;
    fresh.rgb = Rgb16::load(first);
    if (nir_) fresh.nir = load_le<std::uint16_t>(first + 6);
    channels_.reset(context, std::move(fresh));
  }

  void decode(unsigned char* out, int& context) override {
    Context& c = channels_.follow(context);
    Context& last = channels_.last();
    if (rgb_.present) last.rgb = decode_rgb_v2(rgb_.dec, c.coder, last.rgb);
    last.rgb.store(out);
    if (!nir_) return;
    if (nir_layer_.present) {
      ArithmeticDecoder& d = nir_layer_.dec;
      const std::uint32_t used = d.decode_symbol(c.nir_used);
      const int lo = (used & 1) ? fold_u8(static_cast<int>(d.decode_symbol(c.nir_diff[0])) + (last.nir & 0xFF)) : (last.nir & 0xFF);
      const int hi = (used & 2) ? fold_u8(static_cast<int>(d.decode_symbol(c.nir_diff[1])) + (last.nir >> 8)) : (last.nir >> 8);
      last.nir = static_cast<std::uint16_t>(lo | (hi << 8));
    }
    store_le(out + 6, last.nir);
  }

  std::uint32_t overrun() const override { return rgb_.overrun() + nir_layer_.overrun(); }

 private:
  struct Context {
    Rgb16 rgb;
    std::uint16_t nir = 0;
    RgbCoder coder;
    SymbolModel nir_used{4};
    std::array<SymbolModel, 2> nir_diff{SymbolModel(256), SymbolModel(256)};
    Context fresh_copy() const {
      Context c;
      c.rgb = rgb;
      c.nir = nir;
      return c;
    }
  };
  bool nir_;
  LayerDecoder rgb_, nir_layer_;
  ChannelFollower<Context> channels_;
};

class Byte14V3 final : public LayeredItem {
 public:
  explicit Byte14V3(std::size_t n) : n_(n), layer_(n) {}
  std::size_t layer_count() const override { return n_; }

  void start(const unsigned char* first, const std::vector<Layer>& layers, int context) override {
    for (std::size_t i = 0; i < n_; ++i) layer_[i].start(layers[i]);
    channels_.reset(context, Context(first, n_));
  }

  void decode(unsigned char* out, int& context) override {
    Context& c = channels_.follow(context);
    Context& last = channels_.last();
    for (std::size_t i = 0; i < n_; ++i) {
      if (layer_[i].present) last.bytes[i] = fold_u8(last.bytes[i] + static_cast<int>(layer_[i].dec.decode_symbol(c.models[i])));
      out[i] = last.bytes[i];
    }
  }

  std::uint32_t overrun() const override {
    std::uint32_t total = 0;
    for (const auto& l : layer_) total += l.overrun();
    return total;
  }

 private:
  struct Context {
    std::vector<std::uint8_t> bytes;
    std::vector<SymbolModel> models;
    Context(const unsigned char* b, std::size_t n) : bytes(b, b + n) {
      models.reserve(n);
      for (std::size_t i = 0; i < n; ++i) models.emplace_back(256);
    }
    Context fresh_copy() const { return Context(bytes.data(), bytes.size()); }
  };
  std::size_t n_;
  std::vector<LayerDecoder> layer_;
  ChannelFollower<Context> channels_;
};

}  // namespace

std::unique_ptr<LayeredItem> make_layered_item(const Item& item) {
  if (item.version != 3) return nullptr;
  switch (item.type) {
    case kPoint14: return item.size == 30 ? std::make_unique<Point14V3>() : nullptr;
    case kRgb14: return item.size == 6 ? std::make_unique<Rgb14V3>(false) : nullptr;
    case kRgbNir14: return item.size == 8 ? std::make_unique<Rgb14V3>(true) : nullptr;
    case kByte14: return item.size > 0 ? std::make_unique<Byte14V3>(item.size) : nullptr;
    default: return nullptr;
  }
}

}  // namespace hsr::laz
