// Float<E, M> min or max unit (MAX = 0: min, 1: max): a comparator and a multiplexer, as
// fixedfloat defines them, min = (b < a) ? b : a, max = (a < b) ? b : a, on the flushed operands.
// So min(x, NaN) = x, min(NaN, x) = NaN (its encoding passed on), min(+0, -0) = +0. The output
// follows the inputs by exactly LAT cycles (LAT >= 1; lat.cmp defaults to 1).
module fp_minmax #(
    parameter int E     = 7,
    parameter int M     = 16,
    parameter int LAT   = 1,
    parameter bit FLUSH = 1'b1,
    parameter bit MAX   = 1'b0
) (
    input  logic         clk,
    input  logic         rst,
    input  logic         in_valid,
    input  logic [E+M:0] a,
    input  logic [E+M:0] b,
    output logic         out_valid,
    output logic [E+M:0] y
);
  logic take_b;
  /* verilator lint_off UNUSEDSIGNAL */
  logic eq;
  /* verilator lint_on UNUSEDSIGNAL */
  logic [E+M:0] fx, fy;
  // min asks b < a, max asks a < b: the comparator sees (x, y) = (b, a) or (a, b); the
  // multiplexer takes b when it answers yes.
  fp_cmp_core #(.E(E), .M(M), .FLUSH(FLUSH)) u_core (
      .a(MAX ? a : b), .b(MAX ? b : a), .lt(take_b), .eq(eq), .fa(fx), .fb(fy)
  );
  // fx, fy: the flushed (a, b) or (b, a).
  logic [E+M:0] fa, fb;
  assign fa = MAX ? fx : fy;
  assign fb = MAX ? fy : fx;
  fp_stage #(.W(E + M + 1), .N(LAT)) u_rout (.clk(clk), .d(take_b ? fb : fa), .q(y));
  fp_valid #(.N(LAT)) u_valid (.clk(clk), .rst(rst), .d(in_valid), .q(out_valid));
endmodule
