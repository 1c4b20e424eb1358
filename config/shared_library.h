// A client library loaded when first used (dlopen), not at start-up.
//
// libpq (the fleet upload) and libcurl (the weather fetch) are used by few
// commands, but a linked library is mapped and relocated by every pvtwin
// process, with all its dependencies: the two bring 34 more, most of the
// binary's start-up time (doc/performance.md). Loaded on demand, they cost
// a `calibrate` or a `simulate` nothing.
//
// The headers still come from the -dev packages at build time, so each
// function pointer has the exact type of the declaration it stands for.
#pragma once

#include <string>

namespace pvtwin {

class SharedLibrary {
 public:
  // Loads `soname` (e.g. "libpq.so.5"); throws std::runtime_error naming it,
  // the Debian package that installs it and the loader's reason.
  SharedLibrary(const char* soname, const char* package);
  // The library stays loaded for the life of the process: libcurl and the TLS
  // libraries under it are not made to be unloaded.
  SharedLibrary(const SharedLibrary&) = delete;
  SharedLibrary& operator=(const SharedLibrary&) = delete;

  // Points *fn at the function `name`; throws std::runtime_error when the
  // library has no such symbol (a library older than the headers).
  template <typename F>
  void Bind(F** fn, const char* name) const {
    *fn = reinterpret_cast<F*>(Symbol(name));
  }

 private:
  void* Symbol(const char* name) const;

  std::string soname_;
  void* handle_ = nullptr;
};

}  // namespace pvtwin
