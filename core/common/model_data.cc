#include "core/common/model_data.h"

#include <cstdio>
#include <cstdlib>

namespace pvtwin {

std::vector<double>& RunInputs::Scratch() {
  if (work == nullptr || work_used >= work->size()) {
    std::fprintf(stderr, "RunInputs::Scratch: more than %zu work vectors; raise kRunWorkVectors\n",
                 kRunWorkVectors);
    std::abort();
  }
  return (*work)[work_used++];
}

double* RunInputs::Own(const double** field) {
  for (std::size_t k = 0; k < work_used; ++k) {
    if ((*work)[k].data() == *field) return (*work)[k].data();
  }
  std::vector<double>& v = Scratch();
  v.assign(*field, *field + n);
  *field = v.data();
  return v.data();
}

}  // namespace pvtwin
