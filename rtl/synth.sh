#!/usr/bin/env bash
# Yosys synthesis of each float operator and unit datapath (fp24, round to nearest even,
# subnormals flushed, the cycle model's latencies: the SystemVerilog parameter defaults), printing
# a markdown table (docs/rtl.md "Synthesis").
#   rtl/synth.sh [TOP...]        generic gates (yosys `synth`): cells and flip-flops
#   RTL_SYNTH=xc2v rtl/synth.sh  Xilinx Virtex-II, the paper's prototype family (yosys
#                                `synth_xilinx -family xc2v`, experimental): LUTs, flip-flops,
#                                MULT18X18 blocks
#   RTL_NETLIST_DIR=DIR          also writes each flattened netlist as DIR/TOP.v
# Default tops: every operator and unit (generic: about 4 minutes; xc2v: longer).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
fp=(fp_pkg fp_stage fp_valid fp_lzc fp_class fp_normalize fp_round fp_finish fp_add fp_mul fp_div
    fp_cmp_core fp_cmp fp_minmax)
tops=("$@")
if [ ${#tops[@]} -eq 0 ]; then
  tops=(fp_add fp_mul fp_div fp_cmp fp_minmax traversal_unit transform_unit intersection_unit)
fi
target="${RTL_SYNTH:-generic}"
case "$target" in
  generic) synth="synth -flatten" ;;
  xc2v) synth="synth_xilinx -family xc2v -flatten" ;;
  *) echo "synth.sh: RTL_SYNTH is generic or xc2v, not '$target'" >&2; exit 1 ;;
esac
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
files=()
for f in "${fp[@]}"; do files+=("$here/$f.sv"); done
if [ "$target" = generic ]; then
  echo "| top | cells | flip-flops | yosys s |"
  echo "|---|---:|---:|---:|"
else
  echo "| top | LUTs | flip-flops | MULT18X18 | yosys s |"
  echo "|---|---:|---:|---:|---:|"
fi
for top in "${tops[@]}"; do
  extra=()
  case "$top" in *_unit) extra=("$here/$top.sv") ;; esac
  write=""
  if [ -n "${RTL_NETLIST_DIR:-}" ]; then
    mkdir -p "$RTL_NETLIST_DIR"
    write="; write_verilog -noattr $RTL_NETLIST_DIR/$top.v"
  fi
  start=$(date +%s.%N)
  yosys -q -p "read_verilog -sv ${files[*]} ${extra[*]}; hierarchy -top $top;
               $synth -top $top; tee -q -o $tmp/$top.stat stat$write" > "$tmp/$top.log" 2>&1 || {
    cat "$tmp/$top.log" >&2
    exit 1
  }
  end=$(date +%s.%N)
  secs=$(awk -v a="$start" -v b="$end" 'BEGIN {printf "%.0f", b - a}')
  cells=$(awk '/Number of cells:/ {n = $4} END {print n}' "$tmp/$top.stat")
  if [ "$target" = generic ]; then
    ffs=$(awk '$1 ~ /DFF/ {n += $2} END {print n + 0}' "$tmp/$top.stat")
    echo "| $top | $cells | $ffs | $secs |"
  else
    luts=$(awk '$1 ~ /^LUT[0-9]$/ {n += $2} END {print n + 0}' "$tmp/$top.stat")
    ffs=$(awk '$1 ~ /^FD/ {n += $2} END {print n + 0}' "$tmp/$top.stat")
    mults=$(awk '$1 ~ /^MULT18X18/ {n += $2} END {print n + 0}' "$tmp/$top.stat")
    echo "| $top | $luts | $ffs | $mults | $secs |"
  fi
done
