// Lines the benchmark program prints after its runs, from figures its benchmarks leave behind
// (testbench_bench has one main, in render_bench.cpp).
#pragma once

namespace saarcor::testbench {

// The functional fp24 model's rays per second beside the float reference's, with the ratio
// (functional_model_bench.cpp), when both benchmarks ran.
void print_functional_model_ratio();

}  // namespace saarcor::testbench
