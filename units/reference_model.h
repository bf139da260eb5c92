// The functional frame on the reference datapath (ThreadProgram<F, kLanes, ReferenceDatapath>,
// units/reference_datapath.h): every traversal, clip, transformation and RGS step on encodings in
// the paper's op order, lane by lane. Built in its own target, saarcor_units_reference
// (units/reference_model.cpp), which is compiled so that it cannot see units/fast_paths.h
// (units/reference_guard/); testbench/reference_datapath_test.cpp compares its frames with
// run_functional's step by step. fp24 only: the format the check runs in.
#pragma once

#include "fixedfloat/float.h"
#include "memif/image_format.h"
#include "units/functional_model.h"

namespace saarcor::units {

// As run_functional<ff::fp24> (same frame, same counters, same taps), on the reference datapath.
FunctionalFrame run_reference(const memif::MemoryImage& image, const FunctionalParams& params,
                              UnitTap<ff::fp24>* tap = nullptr);

}  // namespace saarcor::units
