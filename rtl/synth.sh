#!/usr/bin/env bash
# Yosys synthesis of each float operator, unit datapath and whole unit (fp24, round to nearest
# even, subnormals flushed, the cycle model's latencies: the SystemVerilog parameter defaults),
# printing a markdown table (docs/rtl.md "Synthesis").
#   rtl/synth.sh [TOP...]        generic gates (yosys `synth`): cells and flip-flops
#   RTL_SYNTH=xc2v rtl/synth.sh  Xilinx Virtex-II, the paper's prototype family (yosys
#                                `synth_xilinx -family xc2v`, experimental): LUTs, flip-flops,
#                                MULT18X18 blocks, block RAMs (RAMB16) and the bits held in LUT
#                                RAM (RAM16X1S ... RAM64X1D)
#   RTL_PARAMS="K=V ..."         parameters set on every TOP (yosys chparam), e.g.
#                                RTL_PARAMS="THREADS=2 STACK=4" rtl/synth.sh traversal_ctrl
#   RTL_NETLIST_DIR=DIR          also writes each flattened netlist as DIR/TOP.v
#   RTL_LOG_DIR=DIR              keeps yosys's log and statistics of each top as DIR/TOP.{log,stat}
# Tops: the operators (fp_add ...), the datapaths (*_unit), and the whole units traversal_ctrl
# (P lanes, the stack, the per-thread state), list_unit (the thread machinery, the mailboxes),
# transformation_threads and intersection_threads (the thread machinery around the datapaths),
# cache (one per-type cache: RTL_PARAMS="WAYS=1 WORDS=2" is the prototype's kd-node cache),
# routing (the simple routing between the caches and the controller port).
# Default tops: every operator and datapath (generic: about 4 minutes; xc2v: longer); the whole
# units only when named (traversal_ctrl takes minutes even with 2 threads; list_unit.sv's own
# default is 16 threads, the prototype's 64 is RTL_PARAMS="THREADS=64").
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
chparam=""
for kv in ${RTL_PARAMS:-}; do
  if [[ ! "$kv" =~ ^[A-Z_][A-Z0-9_]*=[0-9]+$ ]]; then
    echo "synth.sh: RTL_PARAMS takes NAME=NUMBER words, not '$kv'" >&2
    exit 1
  fi
  chparam+=" -set ${kv%%=*} ${kv#*=}"
done
if [ -n "${RTL_LOG_DIR:-}" ]; then
  mkdir -p "$RTL_LOG_DIR"
  tmp="$(cd "$RTL_LOG_DIR" && pwd)"
else
  tmp="$(mktemp -d)"
  trap 'rm -rf "$tmp"' EXIT
fi
files=()
for f in "${fp[@]}"; do files+=("$here/$f.sv"); done
sources() {  # the files a top needs beside the operators
  case "$1" in
    list_unit) echo "$here/unit_threads.sv $here/list_mailbox.sv $here/list_unit.sv" ;;
    traversal_ctrl) echo "$here/traversal_unit.sv $here/traversal_ctrl.sv" ;;
    transformation_threads)
      echo "$here/transform_unit.sv $here/unit_threads.sv $here/transformation_threads.sv" ;;
    intersection_threads)
      echo "$here/intersection_unit.sv $here/unit_threads.sv $here/intersection_threads.sv" ;;
    traversal_unit | transform_unit | intersection_unit | cache | routing) echo "$here/$1.sv" ;;
    fp_*) echo "" ;;
    *) return 1 ;;
  esac
}
for top in "${tops[@]}"; do
  sources "$top" > /dev/null || { echo "synth.sh: unknown top '$top'" >&2; exit 1; }
done
if [ "$target" = generic ]; then
  echo "| top | cells | flip-flops | yosys CPU s |"
  echo "|---|---:|---:|---:|"
else
  echo "| top | LUTs | flip-flops | MULT18X18 | RAMB16 | LUT RAM bits | yosys CPU s |"
  echo "|---|---:|---:|---:|---:|---:|---:|"
fi
for top in "${tops[@]}"; do
  read -r -a extra <<< "$(sources "$top")"
  # The synth pass elaborates the top; an explicit hierarchy pass after chparam would rename it.
  elaborate="hierarchy -top $top;"
  [ -n "$chparam" ] && elaborate="chparam$chparam $top;"
  # traversal_ctrl on Virtex-II: synth_xilinx without its `share` pass. yosys 0.23's share
  # enumerates the activation patterns of the per-thread state's read ports (139,489 for one of
  # them with 2 threads) and ran out of 22 GB; share only merges mutually exclusive read ports
  # and multipliers, so leaving it out can only add cells.
  run="$synth -top $top"
  if [ "$target" = xc2v ] && [ "$top" = traversal_ctrl ]; then
    run="$synth -top $top -run :coarse; techmap -map +/cmp2lut.v -map +/cmp2lcu.v -D LUT_WIDTH=4;
         alumacc; opt; memory -nomap; opt_clean; $synth -top $top -run map_memory:"
  fi
  write=""
  if [ -n "${RTL_NETLIST_DIR:-}" ]; then
    mkdir -p "$RTL_NETLIST_DIR"
    write="; write_verilog -noattr $RTL_NETLIST_DIR/$top.v"
  fi
  yosys -p "read_verilog -sv ${files[*]} ${extra[*]}; $elaborate
               $run; tee -q -o $tmp/$top.stat stat$write" > "$tmp/$top.log" 2>&1 || {
    err=$(grep -m 1 "ERROR" "$tmp/$top.log" || tail -n 1 "$tmp/$top.log")
    echo "synth.sh: yosys failed on $top: $err" >&2
    exit 1
  }
  # yosys's own CPU time (user + system), not the wall clock of a shared host.
  secs=$(awk '/^End of script/ {for (i = 1; i <= NF; i++) if ($i == "user" || $i == "system")
              {t += $(i + 1)}} END {printf "%.0f", t}' "$tmp/$top.log")
  cells=$(awk '/Number of cells:/ {n = $4} END {print n}' "$tmp/$top.stat")
  if [ "$target" = generic ]; then
    ffs=$(awk '$1 ~ /DFF/ {n += $2} END {print n + 0}' "$tmp/$top.stat")
    echo "| $top | $cells | $ffs | $secs |"
  else
    luts=$(awk '$1 ~ /^LUT[0-9]$/ {n += $2} END {print n + 0}' "$tmp/$top.stat")
    ffs=$(awk '$1 ~ /^FD/ {n += $2} END {print n + 0}' "$tmp/$top.stat")
    mults=$(awk '$1 ~ /^MULT18X18/ {n += $2} END {print n + 0}' "$tmp/$top.stat")
    brams=$(awk '$1 ~ /^RAMB16/ {n += $2} END {print n + 0}' "$tmp/$top.stat")
    # RAMnnX1S/D: nn bits each (a dual-port one holds its nn bits twice, in two LUTs).
    lutram=$(awk 'match($1, /^RAM[0-9]+X1[SD]/) {b = substr($1, 4); sub(/X.*/, "", b);
                  n += b * $2} END {print n + 0}' "$tmp/$top.stat")
    echo "| $top | $luts | $ffs | $mults | $brams | $lutram | $secs |"
  fi
done
