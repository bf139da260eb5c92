// Rounding and packing (combinational): kept (M+1 bits, hidden bit first) at biased exponent
// e >= 1, with the guard and sticky bits below it. RNE = 1 rounds to nearest, ties to even; 0
// truncates (toward zero). A carry out of the significand bumps the exponent field (a subnormal
// that rounds up to the smallest normal stays normal); a field reaching all ones overflows to
// +-inf (RNE) or +-largest finite (truncation). FLUSH = 1 writes a result that is subnormal after
// rounding as a zero of the same sign.
module fp_round #(
    parameter int E     = 7,
    parameter int M     = 16,
    parameter bit RNE   = 1'b1,
    parameter bit FLUSH = 1'b1,
    parameter int XW    = fp_pkg::xw(E, M)
) (
    input  logic          sign,
    input  logic [XW-1:0] e,
    input  logic [   M:0] kept,
    input  logic          guard,
    input  logic          sticky,
    output logic [ E+M:0] y
);
  localparam logic [XW+M:0] InfMag = (XW + M + 1)'(((1 << E) - 1)) << M;
  localparam logic [XW+M:0] MinNormal = (XW + M + 1)'(1) << M;

  logic [XW-1:0] e_m1;
  logic          inc;
  logic [XW+M:0] mag;
  logic          overflow;
  logic          subnormal;

  assign inc       = RNE & guard & (sticky | kept[0]);
  // The hidden bit adds into the exponent field: field = e - 1 + hidden (+ a rounding carry).
  assign e_m1      = e - XW'(1);
  assign mag       = ((XW + M + 1)'(e_m1) << M) + (XW + M + 1)'(kept) + (XW + M + 1)'(inc);
  assign overflow  = mag >= InfMag;
  assign subnormal = mag < MinNormal;

  always_comb begin
    if (overflow) y = {sign, RNE ? InfMag[E+M-1:0] : InfMag[E+M-1:0] - 1'b1};
    else if (FLUSH && subnormal) y = {sign, {(E + M) {1'b0}}};
    else y = {sign, mag[E+M-1:0]};
  end
endmodule
