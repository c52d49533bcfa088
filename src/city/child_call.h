// Internal to stage city: a call made in a short-lived child process, its answer handed back as plain data.
//
// Why: footprints.cpp's GDAL questions (reading a footprint file, a CRS's EPSG code and units) load the GDAL
// module, which maps libgdal and about 100 libraries it links (PROJ, GEOS, xerces, poppler, ...): about 30 MB
// that stay mapped, and charged to the process, until it ends (DECISIONS #244). In `hsr city`'s driver that was
// a third of the run's memory summed over its processes at `-j 1`; asked in a child, the libraries go with it.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <string>

namespace hsr {

/// Forks a child that runs `call` and hands its answer back through a pipe (CBOR: numbers to the bit), then
/// returns it; the child ends with _exit, running no destructor or exit handler of this process. A call that
/// throws hsr::Error throws the same Error here (status, stage, message); any other exception is
/// Error(Internal, "city") with its message. A child that ends without an answer (a crash, a signal) is
/// Error(Internal, "city") naming `what` and the signal; a fork or pipe that fails, Error(Internal, "city")
/// naming the reason. Forking copies only the calling thread: the call must need nothing another thread of
/// this process could be holding (the GDAL calls need only their own module's state and malloc, which fork
/// leaves usable).
nlohmann::json call_in_child(const std::string& what, const std::function<nlohmann::json()>& call);

}  // namespace hsr
