#include "config/shared_library.h"

#include <dlfcn.h>

#include <stdexcept>

namespace pvtwin {

SharedLibrary::SharedLibrary(const char* soname, const char* package) : soname_(soname) {
  handle_ = dlopen(soname, RTLD_NOW | RTLD_LOCAL);
  if (handle_ == nullptr) {
    const char* why = dlerror();
    throw std::runtime_error(soname_ + " could not be loaded (Debian package " + package +
                             "): " + (why != nullptr ? why : "no reason given"));
  }
}

void* SharedLibrary::Symbol(const char* name) const {
  dlerror();  // clears an earlier error
  void* symbol = dlsym(handle_, name);
  if (symbol == nullptr) {
    const char* why = dlerror();
    throw std::runtime_error(soname_ + " has no function " + name + ": " +
                             (why != nullptr ? why : "null symbol"));
  }
  return symbol;
}

}  // namespace pvtwin
