// Parameters <-> JSON, written once per Params struct (issue 15: the run report writes every stage's
// parameters with it and `hsr reconstruct --config REPORT.json` reads them back, so the two cannot
// drift). A stage lists its fields once, in its <stage>_params.cpp:
//
//   template <class P, class F> void fields(P& p, F&& f) { f("lambda", p.lambda); f("merge_coplanar", ...); }
//   void to_json(nlohmann::json& j, const ExtractionParams& p) { params_json::write(j, p, fields<...>); }
//
// and to_json / from_json (declared next to the struct) call write() / read() below with that list.
// Values are the struct's own (relative units as documented in the stage header; the resolved absolute
// values are in the report's `resolved` section). Doubles are written with 17 significant digits, so a
// value read back is the same double.
#pragma once

#include "core/error.h"
#include "core/types.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

namespace hsr::params_json {

/// Writes every field it is given into a JSON object.
struct Writer {
  nlohmann::json& j;
  template <class T>
  void operator()(const char* key, const T& value) const {
    j[key] = value;
  }
  void operator()(const char* key, double value) const {  // NaN ("none given") as null, not as a number
    j[key] = std::isnan(value) ? nlohmann::json(nullptr) : nlohmann::json(value);
  }
  void operator()(const char* key, const std::vector<Vec3>& points) const {
    nlohmann::json a = nlohmann::json::array();
    for (const Vec3& p : points) a.push_back({p.x(), p.y(), p.z()});
    j[key] = std::move(a);
  }
};

/// Reads every field it is given that the object holds (a missing key keeps the field's value); a value
/// of the wrong type is Error(BadInput, "config") naming parameters.<stage>.<key>, and so (in finish())
/// is a key no field has.
class Reader {
 public:
  Reader(const nlohmann::json& j, std::string stage) : j_(j), stage_(std::move(stage)) {
    if (!j_.is_object()) fail("", "is not a JSON object");
  }
  template <class T>
  void operator()(const char* key, T& value) {
    known_.insert(key);
    const auto it = j_.find(key);
    if (it == j_.end()) return;
    if constexpr (std::is_floating_point_v<T>) {
      if (it->is_null()) {  // written for NaN ("none given")
        value = std::numeric_limits<T>::quiet_NaN();
        return;
      }
    }
    if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {  // no silent truncation or wrap
      if (!it->is_number_integer() || (std::is_unsigned_v<T> && !it->is_number_unsigned()))
        fail(key, "must be " + std::string(std::is_unsigned_v<T> ? "a non-negative" : "an") + " integer, not " + it->dump());
    }
    try {
      value = it->template get<T>();
    } catch (const nlohmann::json::exception& e) {
      fail(key, std::string("cannot be read from ") + it->dump() + " (" + e.what() + ")");
    }
  }
  void operator()(const char* key, std::vector<Vec3>& points) {
    known_.insert(key);
    const auto it = j_.find(key);
    if (it == j_.end()) return;
    std::vector<Vec3> out;
    if (it->is_array())
      for (const auto& p : *it) {
        if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number())
          fail(key, "must be a list of [x, y, z]");
        out.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
      }
    else
      fail(key, "must be a list of [x, y, z]");
    points = std::move(out);
  }
  void finish() const {
    for (const auto& [key, value] : j_.items())
      if (!known_.count(key)) fail(key, "is not a parameter of this stage");
  }

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw Error(Status::BadInput, "config", "parameters." + stage_ + (key.empty() ? "" : "." + key) + " " + what);
  }
  const nlohmann::json& j_;
  std::string stage_;
  std::set<std::string> known_;
};

/// to_json of a Params struct from its field list.
template <class P, class Fields>
void write(nlohmann::json& j, const P& params, Fields&& fields) {
  j = nlohmann::json::object();
  fields(params, Writer{j});
}

/// from_json of a Params struct from its field list (`stage` names it in error messages).
template <class P, class Fields>
void read(const nlohmann::json& j, P& params, const char* stage, Fields&& fields) {
  Reader reader(j, stage);
  fields(params, reader);
  reader.finish();
}

}  // namespace hsr::params_json
