// Float<E, M> comparator unit: lt, le, eq of fixedfloat (NaN: all false; -0 == +0; subnormals as
// zeros in flush mode). The outputs follow the inputs by exactly LAT cycles (LAT >= 1; the cycle
// model's lat.cmp defaults to 1: the compare, then the output register).
module fp_cmp #(
    parameter int E     = 7,
    parameter int M     = 16,
    parameter int LAT   = 1,
    parameter bit FLUSH = 1'b1
) (
    input  logic         clk,
    input  logic         rst,
    input  logic         in_valid,
    input  logic [E+M:0] a,
    input  logic [E+M:0] b,
    output logic         out_valid,
    output logic         lt,
    output logic         le,
    output logic         eq
);
  logic c_lt, c_eq;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [E+M:0] fa, fb;
  /* verilator lint_on UNUSEDSIGNAL */
  fp_cmp_core #(.E(E), .M(M), .FLUSH(FLUSH)) u_core (
      .a(a), .b(b), .lt(c_lt), .eq(c_eq), .fa(fa), .fb(fb)
  );
  fp_stage #(.W(3), .N(LAT)) u_rout (.clk(clk), .d({c_lt, c_lt | c_eq, c_eq}), .q({lt, le, eq}));
  fp_valid #(.N(LAT)) u_valid (.clk(clk), .rst(rst), .d(in_valid), .q(out_valid));
endmodule
