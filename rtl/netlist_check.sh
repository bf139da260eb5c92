#!/usr/bin/env bash
# Checks that yosys reads the SystemVerilog as Verilator does: synthesises fp_ops_top (every
# operator) to a flattened gate netlist with yosys `synth`, simulates the netlist with Verilator
# and runs it through rtl/fp_ops_rig.h against fixedfloat: fp24 (nearest even, flush) on the edge
# pairs and 1M generated pairs, and e4m5 (toward zero, keep) on every pair. So the synthesis
# figures of rtl/synth.sh (docs/rtl.md) count logic that is bit-exact too. About a minute.
#   rtl/netlist_check.sh [BUILD_DIR]   (default build-rtl; needs its fixedfloat/units libraries)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
build="$(cd "${1:-$root/build-rtl}" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
files=()
for f in fp_pkg fp_stage fp_valid fp_lzc fp_class fp_normalize fp_round fp_finish fp_add fp_mul \
         fp_div fp_cmp_core fp_cmp fp_minmax fp_ops_top; do
  files+=("$here/$f.sv")
done
synth() {  # name, chparam settings
  yosys -q -p "read_verilog -sv ${files[*]}; chparam $2 fp_ops_top; hierarchy -top fp_ops_top;
               synth -flatten -top fp_ops_top; write_verilog -noattr $work/$1.v" \
    2>&1 | grep -v "Replacing memory" || true
  verilator --cc -Wno-fatal -Wno-lint -Wno-style --prefix "V$1" --top-module fp_ops_top \
    --Mdir "$work/obj_$1" "$work/$1.v" > /dev/null
  make -s -C "$work/obj_$1" -f "V$1.mk" OPT_FAST=-O2 > /dev/null
}
synth net_fp24 "-set E 7 -set M 16 -set RNE 1 -set FLUSH 1"
synth net_e4m5 "-set E 4 -set M 5 -set RNE 0 -set FLUSH 0"
cat > "$work/main.cpp" <<'CPP'
#include <gtest/gtest.h>

#include "Vnet_e4m5.h"
#include "Vnet_fp24.h"
#include "rtl/fp_ops_rig.h"

using namespace saarcor;
using namespace saarcor::rtl::testing;

TEST(Netlist, Fp24NearestEvenFlush) {
  OpsRig<Vnet_fp24, ff::fp24> rig({ff::Rounding::kNearestEven, ff::Subnormals::kFlush},
                                  "netlist fp24");
  run_fp24(rig, 1000000, 77);
}
TEST(Netlist, E4M5TowardZeroKeepExhaustive) {
  OpsRig<Vnet_e4m5, ff::Float<4, 5>> rig({ff::Rounding::kTowardZero, ff::Subnormals::kKeep},
                                         "netlist e4m5");
  for (std::uint32_t a = 0; a < 1024; ++a)
    for (std::uint32_t b = 0; b < 1024; ++b)
      rig.issue(a, b);
  rig.finish();
}
CPP
vinc=/usr/share/verilator/include
g++ -std=c++20 -O2 -I"$root" -I"$work/obj_net_fp24" -I"$work/obj_net_e4m5" -isystem "$vinc" \
  -isystem "$vinc/vltstd" "$work/main.cpp" "$work/obj_net_fp24/Vnet_fp24__ALL.a" \
  "$work/obj_net_e4m5/Vnet_e4m5__ALL.a" "$vinc/verilated.cpp" "$vinc/verilated_threads.cpp" \
  "$build/units/libsaarcor_units.a" "$build/hw/libsaarcor_hw.a" \
  "$build/memif/libsaarcor_memif.a" "$build/fixedfloat/libsaarcor_fixedfloat.a" \
  -lgtest_main -lgtest -lpthread -latomic -o "$work/netlist_check"
"$work/netlist_check"
