// The reference instantiation of the functional model (units/reference_model.h). This translation
// unit is the whole of target saarcor_units_reference: it sees the reference datapath policy and
// the policy-free unit semantics, and is compiled with units/reference_guard/ first on the quote
// include path, whose units/fast_paths.h stops the build (units/CMakeLists.txt). A fast path
// reached from here, through any header, would not compile.
#include "units/reference_model.h"

#include "units/frame_loop.h"
#include "units/reference_datapath.h"

namespace saarcor::units {

FunctionalFrame run_reference(const memif::MemoryImage& image, const FunctionalParams& params,
                              UnitTap<ff::fp24>* tap) {
  return run_frame<ff::fp24, ReferenceDatapath>(image, params, {}, tap, nullptr);
}

}  // namespace saarcor::units
