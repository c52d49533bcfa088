// The entropy coder of the LASzip compressed format (LAZ), decoding side: the adaptive arithmetic decoder
// (Amir Said's FastAC as LASzip uses it: 32-bit interval, bytes shifted in most significant first), its
// adaptive bit and symbol models, the integer decompressor that codes a corrector to a prediction in
// "k bits" classes, and the streaming median of five used by the point items. Written from the published
// format (LASzip's specification of its item coders); every constant below is part of the format.
//
// Robustness: decoding never reads outside [begin, end): past the end it is fed zero bytes and counts them
// (overrun()), so a truncated or corrupt chunk decodes to garbage of the right size, never out of bounds; the
// caller turns an overrun into an error. Models only ever return symbols below their alphabet size (the
// interval invariant value < length holds for any input bytes), so a decoded symbol can index a table of
// that size.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

namespace hsr::laz {

inline constexpr std::uint32_t kMinLength = 0x01000000u;  ///< renormalise below this interval length
inline constexpr std::uint32_t kMaxLength = 0xFFFFFFFFu;
inline constexpr std::uint32_t kBitLengthShift = 13;  ///< bit models: probabilities of 13 bits
inline constexpr std::uint32_t kBitMaxCount = 1u << kBitLengthShift;
inline constexpr std::uint32_t kSymbolLengthShift = 15;  ///< symbol models: distributions of 15 bits
inline constexpr std::uint32_t kSymbolMaxCount = 1u << kSymbolLengthShift;

/// Adaptive model of one binary decision.
struct BitModel {
  std::uint32_t update_cycle = 4, bits_until_update = 4;
  std::uint32_t bit_0_prob = 1u << (kBitLengthShift - 1), bit_0_count = 1, bit_count = 2;

  void update() {
    if ((bit_count += update_cycle) > kBitMaxCount) {  // halve the counts when they grow too large
      bit_count = (bit_count + 1) >> 1;
      bit_0_count = (bit_0_count + 1) >> 1;
      if (bit_0_count == bit_count) ++bit_count;
    }
    const std::uint32_t scale = 0x80000000u / bit_count;
    bit_0_prob = (bit_0_count * scale) >> (31 - kBitLengthShift);
    update_cycle = (5 * update_cycle) >> 2;  // adapt fast at first, then every 64 bits
    if (update_cycle > 64) update_cycle = 64;
    bits_until_update = update_cycle;
  }
};

/// Adaptive model of a symbol in [0, symbols), symbols in [2, 2048]. Alphabets above 16 symbols carry a
/// look-up table that narrows the search for the decoded symbol.
class SymbolModel {
 public:
  explicit SymbolModel(std::uint32_t symbols) : symbols_(symbols), last_symbol_(symbols - 1) {
    if (symbols > 16) {
      std::uint32_t table_bits = 3;
      while (symbols > (1u << (table_bits + 2))) ++table_bits;
      table_size_ = 1u << table_bits;
      table_shift_ = kSymbolLengthShift - table_bits;
    }
    // One block: distribution, counts, decoder table (table_size + 2 entries when there is one).
    const std::size_t table_entries = table_size_ != 0 ? table_size_ + 2 : 0;
    storage_ = std::make_unique<std::uint32_t[]>(2 * std::size_t{symbols} + table_entries);
    distribution_ = storage_.get();
    count_ = distribution_ + symbols;
    table_ = count_ + symbols;
    for (std::uint32_t k = 0; k < symbols; ++k) count_[k] = 1;
    update_cycle_ = symbols;
    update();
    symbols_until_update_ = update_cycle_ = (symbols + 6) >> 1;
  }

  std::uint32_t symbols() const { return symbols_; }

 private:
  friend class ArithmeticDecoder;

  void update() {
    if ((total_count_ += update_cycle_) > kSymbolMaxCount) {
      total_count_ = 0;
      for (std::uint32_t k = 0; k < symbols_; ++k) total_count_ += (count_[k] = (count_[k] + 1) >> 1);
    }
    const std::uint32_t scale = 0x80000000u / total_count_;
    std::uint32_t sum = 0, s = 0;
    if (table_size_ == 0) {
      for (std::uint32_t k = 0; k < symbols_; ++k) {
        distribution_[k] = (scale * sum) >> (31 - kSymbolLengthShift);
        sum += count_[k];
      }
    } else {
      for (std::uint32_t k = 0; k < symbols_; ++k) {
        distribution_[k] = (scale * sum) >> (31 - kSymbolLengthShift);
        sum += count_[k];
        const std::uint32_t w = distribution_[k] >> table_shift_;
        while (s < w) table_[++s] = k - 1;
      }
      table_[0] = 0;
      while (s <= table_size_) table_[++s] = symbols_ - 1;
    }
    update_cycle_ = (5 * update_cycle_) >> 2;
    const std::uint32_t max_cycle = (symbols_ + 6) << 3;
    if (update_cycle_ > max_cycle) update_cycle_ = max_cycle;
    symbols_until_update_ = update_cycle_;
  }

  std::uint32_t symbols_, last_symbol_;
  std::uint32_t table_size_ = 0, table_shift_ = 0;
  std::uint32_t total_count_ = 0, update_cycle_ = 0, symbols_until_update_ = 0;
  std::unique_ptr<std::uint32_t[]> storage_;
  std::uint32_t* distribution_ = nullptr;
  std::uint32_t* count_ = nullptr;
  std::uint32_t* table_ = nullptr;
};

/// The arithmetic decoder over one byte range.
class ArithmeticDecoder {
 public:
  ArithmeticDecoder() = default;
  ArithmeticDecoder(const unsigned char* begin, const unsigned char* end) { start(begin, end); }

  /// Starts decoding the bytes [begin, end) (reads the first four).
  void start(const unsigned char* begin, const unsigned char* end) {
    next_ = begin;
    end_ = end;
    overrun_ = 0;
    length_ = kMaxLength;
    value_ = 0;
    for (int i = 0; i < 4; ++i) value_ = (value_ << 8) | byte();
  }

  /// Zero bytes fed past the end of the range (0 for a well-formed stream).
  std::uint32_t overrun() const { return overrun_; }

  std::uint32_t decode_bit(BitModel& m) {
    const std::uint32_t x = m.bit_0_prob * (length_ >> kBitLengthShift);
    const std::uint32_t bit = value_ >= x;
    if (bit == 0) {
      length_ = x;
      ++m.bit_0_count;
    } else {
      value_ -= x;
      length_ -= x;
    }
    if (length_ < kMinLength) renormalise();
    if (--m.bits_until_update == 0) m.update();
    return bit;
  }

  std::uint32_t decode_symbol(SymbolModel& m) {
    std::uint32_t sym, n, x, y = length_;
    if (m.table_size_ != 0) {  // table look-up, then bisection
      const std::uint32_t dv = value_ / (length_ >>= kSymbolLengthShift);
      std::uint32_t t = dv >> m.table_shift_;
      if (t > m.table_size_) t = m.table_size_;  // cannot happen (value < length); keeps the index in range
      sym = m.table_[t];
      n = m.table_[t + 1] + 1;
      while (n > sym + 1) {
        const std::uint32_t k = (sym + n) >> 1;
        if (m.distribution_[k] > dv) n = k; else sym = k;
      }
      x = m.distribution_[sym] * length_;
      if (sym != m.last_symbol_) y = m.distribution_[sym + 1] * length_;
    } else {  // bisection by multiplications
      x = sym = 0;
      length_ >>= kSymbolLengthShift;
      n = m.symbols_;
      std::uint32_t k = n >> 1;
      do {
        const std::uint32_t z = length_ * m.distribution_[k];
        if (z > value_) {
          n = k;
          y = z;
        } else {
          sym = k;
          x = z;
        }
      } while ((k = (sym + n) >> 1) != sym);
    }
    value_ -= x;
    length_ = y - x;
    if (length_ < kMinLength) renormalise();
    ++m.count_[sym];
    if (--m.symbols_until_update_ == 0) m.update();
    return sym;
  }

  /// `bits` raw bits (1..32), equiprobable.
  std::uint32_t read_bits(std::uint32_t bits) {
    if (bits > 19) {
      const std::uint32_t low = read_short();
      return (read_bits(bits - 16) << 16) | low;
    }
    const std::uint32_t sym = value_ / (length_ >>= bits);
    value_ -= length_ * sym;
    if (length_ < kMinLength) renormalise();
    return sym;
  }
  std::uint32_t read_short() { return read_bits(16); }
  std::uint32_t read_int() {
    const std::uint32_t low = read_short();
    return (read_short() << 16) | low;
  }
  std::uint64_t read_int64() {
    const std::uint64_t low = read_int();
    return (std::uint64_t{read_int()} << 32) | low;
  }

 private:
  std::uint32_t byte() {
    if (next_ < end_) return *next_++;
    ++overrun_;
    return 0;
  }
  void renormalise() {
    do value_ = (value_ << 8) | byte();
    while ((length_ <<= 8) < kMinLength);
  }

  const unsigned char* next_ = nullptr;
  const unsigned char* end_ = nullptr;
  std::uint32_t value_ = 0, length_ = kMaxLength, overrun_ = 0;
};

/// Codes an integer as a prediction plus a corrector. The corrector's "k" (its bit class: 0 for 0 or 1,
/// else |c| in (2^(k-1), 2^k]) is a symbol under one of `contexts` models; the position within the class
/// is coded by a model of up to 2^bits_high symbols for the high bits and raw bits for the rest. Values
/// wrap modulo 2^bits.
class IntegerDecompressor {
 public:
  explicit IntegerDecompressor(std::uint32_t bits = 16, std::uint32_t contexts = 1, std::uint32_t bits_high = 8)
      : bits_high_(bits_high) {
    if (bits > 0 && bits < 32) {
      corr_bits_ = bits;
      corr_range_ = 1u << bits;
      corr_min_ = -static_cast<std::int32_t>(corr_range_ / 2);
    } else {
      corr_bits_ = 32;
      corr_range_ = 0;
      corr_min_ = INT32_MIN;
    }
    k_models_.reserve(contexts);
    for (std::uint32_t i = 0; i < contexts; ++i) k_models_.emplace_back(corr_bits_ + 1);
    corrector_.resize(corr_bits_);  // created on first use: most bit classes never occur in a chunk
  }

  std::int32_t decompress(ArithmeticDecoder& dec, std::int32_t prediction, std::uint32_t context) {
    std::uint32_t real = static_cast<std::uint32_t>(prediction) + read_corrector(dec, k_models_[context]);
    if (corr_range_ != 0) {  // fold back into [0, 2^bits)
      std::int32_t r = static_cast<std::int32_t>(real);
      if (r < 0) r += static_cast<std::int32_t>(corr_range_);
      else if (static_cast<std::uint32_t>(r) >= corr_range_) r -= static_cast<std::int32_t>(corr_range_);
      return r;
    }
    return static_cast<std::int32_t>(real);
  }

  /// The bit class of the last corrector (the point items use it as a context for the next field).
  std::uint32_t k() const { return k_; }

 private:
  std::uint32_t read_corrector(ArithmeticDecoder& dec, SymbolModel& k_model) {
    k_ = dec.decode_symbol(k_model);
    if (k_ == 0) return dec.decode_bit(corrector0_);  // 0 or 1
    if (k_ >= 32) return static_cast<std::uint32_t>(corr_min_);
    std::unique_ptr<SymbolModel>& model = corrector_[k_ - 1];
    if (!model) model = std::make_unique<SymbolModel>(k_ <= bits_high_ ? 1u << k_ : 1u << bits_high_);
    std::uint32_t c;
    if (k_ <= bits_high_) {
      c = dec.decode_symbol(*model);
    } else {
      const std::uint32_t low_bits = k_ - bits_high_;
      c = dec.decode_symbol(*model) << low_bits;
      c |= dec.read_bits(low_bits);
    }
    // [0, 2^(k-1)) are the negative correctors -(2^k - 1) .. -2^(k-1); [2^(k-1), 2^k) the positive
    // 2^(k-1) + 1 .. 2^k. Unsigned arithmetic wraps as the format does for k = 31.
    if (c >= (1u << (k_ - 1))) return c + 1;
    return c - ((1u << k_) - 1);
  }

  std::uint32_t bits_high_, corr_bits_, corr_range_;
  std::int32_t corr_min_;
  std::uint32_t k_ = 0;
  std::vector<SymbolModel> k_models_;
  BitModel corrector0_;
  std::vector<std::unique_ptr<SymbolModel>> corrector_;  ///< [k - 1]: the position within bit class k
};

/// The median of the last five values added (starts at five zeros), kept sorted with a toggle that says
/// which end the next value replaces.
class Median5 {
 public:
  std::int32_t get() const { return v_[2]; }
  void add(std::int32_t x) {
    if (high_) {
      if (x < v_[2]) {
        v_[4] = v_[3];
        v_[3] = v_[2];
        if (x < v_[0]) {
          v_[2] = v_[1];
          v_[1] = v_[0];
          v_[0] = x;
        } else if (x < v_[1]) {
          v_[2] = v_[1];
          v_[1] = x;
        } else {
          v_[2] = x;
        }
      } else {
        if (x < v_[3]) {
          v_[4] = v_[3];
          v_[3] = x;
        } else {
          v_[4] = x;
        }
        high_ = false;
      }
    } else {
      if (v_[2] < x) {
        v_[0] = v_[1];
        v_[1] = v_[2];
        if (v_[4] < x) {
          v_[2] = v_[3];
          v_[3] = v_[4];
          v_[4] = x;
        } else if (v_[3] < x) {
          v_[2] = v_[3];
          v_[3] = x;
        } else {
          v_[2] = x;
        }
      } else {
        if (v_[1] < x) {
          v_[0] = v_[1];
          v_[1] = x;
        } else {
          v_[0] = x;
        }
        high_ = true;
      }
    }
  }

 private:
  std::int32_t v_[5] = {0, 0, 0, 0, 0};
  bool high_ = true;
};

/// Lazily created symbol models, one per context value (LASzip creates a model the first time a context
/// occurs; creating it fresh then is the same as having it from the start).
class LazySymbolModels {
 public:
  LazySymbolModels(std::size_t contexts, std::uint32_t symbols) : symbols_(symbols), models_(contexts) {}
  SymbolModel& operator[](std::size_t context) {
    auto& m = models_[context];
    if (!m) m = std::make_unique<SymbolModel>(symbols_);
    return *m;
  }

 private:
  std::uint32_t symbols_;
  std::vector<std::unique_ptr<SymbolModel>> models_;
};

}  // namespace hsr::laz
