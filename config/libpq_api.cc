#include "config/libpq_api.h"

#include "config/shared_library.h"

namespace pvtwin {

namespace {

LibpqApi Load() {
  static const SharedLibrary library("libpq.so.5", "libpq5");
  LibpqApi api;
#define PVTWIN_LIBPQ_BIND(name) library.Bind(&api.name, #name);
  PVTWIN_LIBPQ_FUNCTIONS(PVTWIN_LIBPQ_BIND)
#undef PVTWIN_LIBPQ_BIND
  return api;
}

}  // namespace

const LibpqApi& Libpq() {
  static const LibpqApi api = Load();
  return api;
}

}  // namespace pvtwin
