// Float<E, M> adder/subtracter, bit-exact with fixedfloat's add and sub (docs/rtl.md): y = a + b,
// or a - b when `sub` is set. Fully pipelined (one operation per cycle); y and out_valid follow
// a, b and in_valid by exactly LAT cycles (LAT >= 1; the cycle model's lat.add defaults to 3).
//   stage 1: classify, order the operands by magnitude, align the smaller (guard, round, sticky)
//   stage 2: add or subtract the significands, normalise
//   stage 3: round, pack, special values
// (normalise, round, pack and the special values are the tail every operator shares: fp_finish)
// With LAT < 3 the first boundaries become wires; with LAT > 3 the extra registers follow stage 3.
module fp_add #(
    parameter int E     = 7,
    parameter int M     = 16,
    parameter int LAT   = 3,
    parameter bit RNE   = 1'b1,
    parameter bit FLUSH = 1'b1
) (
    input  logic         clk,
    input  logic         rst,
    input  logic         in_valid,
    input  logic [E+M:0] a,
    input  logic [E+M:0] b,
    input  logic         sub,
    output logic         out_valid,
    output logic [E+M:0] y
);
  localparam int XW = fp_pkg::xw(E, M);
  localparam int R1 = LAT >= 2 ? 1 : 0;
  localparam int R2 = LAT >= 3 ? 1 : 0;
  localparam int ROut = LAT - R1 - R2;

  typedef struct packed {
    logic nan;
    logic inf;
    logic inf_sign;
    logic zero_sign;  // sign of an exact zero sum: -0 only for -0 + -0
    logic eff_sub;
    logic sign;       // the larger operand's
    logic [E-1:0] exp;
    logic [M:0] big;
    logic [M+3:0] little;  // the smaller, aligned: M+1 bits, guard, round, sticky
  } s1_t;

  // ---- stage 1 ----------------------------------------------------------------------------
  logic sa, sb_raw, sb, na, nb, ia, ib;
  logic [E-1:0] ea, eb;
  logic [M:0] ga, gb;
  logic [E+M-1:0] mag_a, mag_b;
  /* verilator lint_off UNUSEDSIGNAL */
  logic za, zb;  // zeros need no flag: their significand is 0 and the sum decides
  /* verilator lint_on UNUSEDSIGNAL */

  fp_class #(.E(E), .M(M), .FLUSH(FLUSH)) u_ca (
      .x(a), .sign(sa), .nan(na), .inf(ia), .zero(za), .exp(ea), .sig(ga), .mag(mag_a)
  );
  fp_class #(.E(E), .M(M), .FLUSH(FLUSH)) u_cb (
      .x(b), .sign(sb_raw), .nan(nb), .inf(ib), .zero(zb), .exp(eb), .sig(gb), .mag(mag_b)
  );
  assign sb = sb_raw ^ sub;

  s1_t s1, s1_q;
  logic swap;
  logic [E-1:0] e_big, e_small, d;
  logic [M+3:0] ext, shifted;
  logic lost;

  always_comb begin
    swap = mag_b > mag_a;
    e_big = swap ? eb : ea;
    e_small = swap ? ea : eb;
    d = e_big - e_small;
    ext = {swap ? ga : gb, 3'b000};
    shifted = ext >> d;
    lost = |(ext & ~({(M + 4) {1'b1}} << d));
    s1.nan = na | nb | (ia & ib & (sa ^ sb));
    s1.inf = ia | ib;
    s1.inf_sign = ia ? sa : sb;
    s1.zero_sign = sa & sb;
    s1.eff_sub = sa ^ sb;
    s1.sign = swap ? sb : sa;
    s1.exp = e_big;
    s1.big = swap ? gb : ga;
    s1.little = {shifted[M+3:1], shifted[0] | lost};
  end

  fp_stage #(.W($bits(s1)), .N(R1)) u_r1 (.clk(clk), .d(s1), .q(s1_q));

  // ---- stage 2: add or subtract the significands; then normalise | round, pack, special
  // values (fp_finish) ---------------------------------------------------------------------
  logic [M+4:0] sum;
  always_comb begin
    if (s1_q.eff_sub) sum = {1'b0, s1_q.big, 3'b000} - {1'b0, s1_q.little};
    else sum = {1'b0, s1_q.big, 3'b000} + {1'b0, s1_q.little};
  end

  // The sum's top bit (the carry) stands for exponent exp + 1.
  fp_finish #(
      .E(E), .M(M), .SW(M + 5), .XW(XW), .RNE(RNE), .FLUSH(FLUSH), .RMID(R2), .ROUT(ROut)
  ) u_finish (
      .clk(clk),
      .nan(s1_q.nan),
      .inf(s1_q.inf),
      .inf_sign(s1_q.inf_sign),
      .zero(~(|sum)),
      .zero_sign(s1_q.zero_sign),
      .sign(s1_q.sign),
      .exp(XW'(s1_q.exp) + XW'(1)),
      .sig(sum),
      .sticky_in(1'b0),
      .y(y)
  );
  fp_valid #(.N(LAT)) u_valid (.clk(clk), .rst(rst), .d(in_valid), .q(out_valid));
endmodule
