// Placeholder until the CUDA backend lands: reports no device, so AUTO picks the CPU.
#include "../src/core/status.h"
#include "cuda_backend.h"

namespace sph {

int cuda_usable_device_count() { return 0; }

std::unique_ptr<Backend> make_cuda_backend(const WorldConfig&, int) {
  throw Error(Status::Unsupported, "backend: the CUDA backend is not implemented yet");
}

}  // namespace sph
