// Float<E, M> multiplier, bit-exact with fixedfloat's mul (docs/rtl.md): y = a * b. Fully
// pipelined; y and out_valid follow the inputs by exactly LAT cycles (LAT >= 1; the cycle model's
// lat.mul defaults to 3).
//   stage 1: classify, multiply the significands (exact 2M+2-bit product), add the exponents
//   stage 2: normalise (subnormal operands: left over leading zeros; underflow: right, sticky)
//   stage 3: round, pack, special values
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
  localparam logic [E+M-1:0] NanMag = {{E{1'b1}}, 1'b1, {(M - 1) {1'b0}}};
  localparam logic [E+M-1:0] InfMag = {{E{1'b1}}, {M{1'b0}}};

  typedef struct packed {
    logic nan;
    logic inf;
    logic zero;
    logic sign;
    logic [XW-1:0] exp;  // biased exponent if the product's top bit (weight 2) is set
    logic [2*M+1:0] prod;
  } s1_t;

  typedef struct packed {
    logic nan;
    logic inf;
    logic zero;
    logic sign;
    logic [XW-1:0] e;
    logic [M:0] kept;
    logic guard;
    logic sticky;
  } s2_t;

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

  // ---- stage 2 ----------------------------------------------------------------------------
  s2_t s2, s2_q;
  logic [XW-1:0] n_e;
  logic [M:0] n_kept;
  logic n_guard, n_sticky;

  fp_normalize #(.E(E), .M(M), .SW(2 * M + 2), .XW(XW)) u_norm (
      .exp(s1_q.exp),
      .sig(s1_q.prod),
      .sticky_in(1'b0),
      .e(n_e),
      .kept(n_kept),
      .guard(n_guard),
      .sticky(n_sticky)
  );

  always_comb begin
    s2.nan = s1_q.nan;
    s2.inf = s1_q.inf;
    s2.zero = s1_q.zero;
    s2.sign = s1_q.sign;
    s2.e = n_e;
    s2.kept = n_kept;
    s2.guard = n_guard;
    s2.sticky = n_sticky;
  end

  fp_stage #(.W($bits(s2)), .N(R2)) u_r2 (.clk(clk), .d(s2), .q(s2_q));

  // ---- stage 3 ----------------------------------------------------------------------------
  logic [E+M:0] rounded, result;
  fp_round #(.E(E), .M(M), .RNE(RNE), .FLUSH(FLUSH), .XW(XW)) u_round (
      .sign(s2_q.sign),
      .e(s2_q.e),
      .kept(s2_q.kept),
      .guard(s2_q.guard),
      .sticky(s2_q.sticky),
      .y(rounded)
  );

  always_comb begin
    if (s2_q.nan) result = {1'b0, NanMag};
    else if (s2_q.inf) result = {s2_q.sign, InfMag};
    else if (s2_q.zero) result = {s2_q.sign, {(E + M) {1'b0}}};
    else result = rounded;
  end

  fp_stage #(.W(E + M + 1), .N(ROut)) u_rout (.clk(clk), .d(result), .q(y));
  fp_valid #(.N(LAT)) u_valid (.clk(clk), .rst(rst), .d(in_valid), .q(out_valid));
endmodule
