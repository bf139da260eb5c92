// Float<E, M> multiplier, bit-exact with fixedfloat's mul (docs/rtl.md): y = a * b. Fully
// pipelined; y and out_valid follow the inputs by exactly LAT cycles (LAT >= 1; the cycle model's
// lat.mul defaults to 3).
//   stage 1: classify, multiply the significands (exact 2M+2-bit product), add the exponents
//   stage 2: normalise (subnormal operands: left over leading zeros; underflow: right, sticky)
//   stage 3: round, pack, special values
// (stages 2 and 3 are the tail every operator shares: fp_finish)
module fp_mul #(
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
    output logic         out_valid,
    output logic [E+M:0] y
);
  localparam int XW = fp_pkg::xw(E, M);
  localparam int Bias = (1 << (E - 1)) - 1;
  localparam int R1 = LAT >= 2 ? 1 : 0;
  localparam int R2 = LAT >= 3 ? 1 : 0;
  localparam int ROut = LAT - R1 - R2;

  typedef struct packed {
    logic nan;
    logic inf;
    logic zero;
    logic sign;
    logic [XW-1:0] exp;  // biased exponent if the product's top bit (weight 2) is set
    logic [2*M+1:0] prod;
  } s1_t;

  // ---- stage 1 ----------------------------------------------------------------------------
  logic sa, sb, na, nb, ia, ib, za, zb;
  logic [E-1:0] ea, eb;
  logic [M:0] ga, gb;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [E+M-1:0] mag_a, mag_b;
  /* verilator lint_on UNUSEDSIGNAL */

  fp_class #(.E(E), .M(M), .FLUSH(FLUSH)) u_ca (
      .x(a), .sign(sa), .nan(na), .inf(ia), .zero(za), .exp(ea), .sig(ga), .mag(mag_a)
  );
  fp_class #(.E(E), .M(M), .FLUSH(FLUSH)) u_cb (
      .x(b), .sign(sb), .nan(nb), .inf(ib), .zero(zb), .exp(eb), .sig(gb), .mag(mag_b)
  );

  s1_t s1, s1_q;
  always_comb begin
    s1.nan  = na | nb | (ia & zb) | (ib & za);
    s1.inf  = ia | ib;
    s1.zero = za | zb;
    s1.sign = sa ^ sb;
    s1.exp  = XW'(ea) + XW'(eb) - XW'(Bias - 1);
    s1.prod = (2 * M + 2)'(ga) * (2 * M + 2)'(gb);
  end

  fp_stage #(.W($bits(s1)), .N(R1)) u_r1 (.clk(clk), .d(s1), .q(s1_q));

  // ---- stages 2 and 3: normalise | round, pack, special values (fp_finish) ----------------
  fp_finish #(
      .E(E), .M(M), .SW(2 * M + 2), .XW(XW), .RNE(RNE), .FLUSH(FLUSH), .RMID(R2), .ROUT(ROut)
  ) u_finish (
      .clk(clk),
      .nan(s1_q.nan),
      .inf(s1_q.inf),
      .inf_sign(s1_q.sign),
      .zero(s1_q.zero),
      .zero_sign(s1_q.sign),
      .sign(s1_q.sign),
      .exp(s1_q.exp),
      .sig(s1_q.prod),
      .sticky_in(1'b0),
      .y(y)
  );
  fp_valid #(.N(LAT)) u_valid (.clk(clk), .rst(rst), .d(in_valid), .q(out_valid));
endmodule
