// Stands in for units/fast_paths.h while target saarcor_units_reference compiles (units/
// CMakeLists.txt puts this folder first on its quote include path): the reference datapath must
// not see the binary64 fast paths, so reaching this header from units/reference_model.cpp is an
// error (docs/functional-model.md, "The reference datapath").
#error "the reference datapath (saarcor_units_reference) includes units/fast_paths.h"
