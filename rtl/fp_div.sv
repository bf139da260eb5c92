// Float<E, M> divider, bit-exact with fixedfloat's div (docs/rtl.md): y = a / b. Fully pipelined;
// y and out_valid follow the inputs by exactly LAT cycles (LAT >= 1; the cycle model's lat.div
// defaults to 8).
//   stage 1: classify, pre-normalise subnormal significands (keep mode), subtract the exponents
//   then:    M+3 restoring division steps (one quotient bit each; the significands are in [1, 2),
//            so the quotient is in (1/2, 2): M+1 bits, the guard bit, one bit for the
//            normalising shift), spread over LAT-2 register stages; the remainder is the sticky bit
//   last:    normalise (at most one left shift, or right into the subnormal range), round, pack,
//            special values (the tail every operator shares: fp_finish)
// With LAT = 8 (fp24) the 19 steps run 3 or 4 per stage. LAT < 3 merges stages; LAT-2 beyond the
// step count adds registers after the last stage.
module fp_div #(
    parameter int E     = 7,
    parameter int M     = 16,
    parameter int LAT   = 8,
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
  localparam int N = M + 3;  // quotient bits
  localparam int R1 = LAT >= 2 ? 1 : 0;
  localparam int NSteps = LAT - 2 < 0 ? 0 : (LAT - 2 > N ? N : LAT - 2);
  localparam int ROut = LAT - R1 - NSteps;
  localparam int CW = $clog2(M + 2);

  typedef struct packed {
    logic nan;
    logic inf;
    logic zero;
    logic sign;
    logic [XW-1:0] exp;  // biased exponent if the quotient is in [1, 2)
    logic [M+1:0] rem;   // partial remainder, < 2 * den
    logic [M:0] den;
    logic [N-1:0] q;
  } st_t;

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

  // Pre-normalised significands (hidden bit set) and exponents; in flush mode every nonzero
  // finite operand is normal already.
  logic [M:0] na_sig, nb_sig;
  logic [XW-1:0] na_exp, nb_exp;
  if (FLUSH) begin : g_flush
    assign na_sig = ga;
    assign nb_sig = gb;
    assign na_exp = XW'(ea);
    assign nb_exp = XW'(eb);
  end else begin : g_keep
    logic [CW-1:0] lza, lzb;
    fp_lzc #(.W(M + 1), .CW(CW)) u_lza (.x(ga), .n(lza));
    fp_lzc #(.W(M + 1), .CW(CW)) u_lzb (.x(gb), .n(lzb));
    assign na_sig = ga << lza;
    assign nb_sig = gb << lzb;
    assign na_exp = XW'(ea) - XW'(lza);
    assign nb_exp = XW'(eb) - XW'(lzb);
  end

  st_t s1, s1_q;
  always_comb begin
    s1.nan  = na | nb | (za & zb) | (ia & ib);
    s1.inf  = ia | zb;
    s1.zero = za | ib;
    s1.sign = sa ^ sb;
    s1.exp  = na_exp - nb_exp + XW'(Bias);
    s1.rem  = {1'b0, na_sig};
    s1.den  = nb_sig;
    s1.q    = '0;
  end

  fp_stage #(.W($bits(s1)), .N(R1)) u_r1 (.clk(clk), .d(s1), .q(s1_q));

  // ---- division steps ---------------------------------------------------------------------
  // chain[i]: the state before step i (after its register, if any).
  localparam int SW = $bits(s1);
  logic [(N+1)*SW-1:0] chain  /*verilator split_var*/;
  assign chain[0+:SW] = s1_q;
  // The state's fields as bit ranges (st_t's layout; no struct inside the generate loop, which
  // yosys 0.23 cannot resolve there): q at the bottom, then den, then rem.
  localparam int DenLo = N;
  localparam int RemLo = N + M + 1;
  for (genvar i = 0; i < N; i++) begin : g_step
    /* verilator lint_off UNUSEDSIGNAL */
    logic [SW-1:0] cur;  // the quotient's top bit is shifted out unused
    /* verilator lint_on UNUSEDSIGNAL */
    logic [SW-1:0] nxt;
    logic [M+1:0] rem, diff;
    logic [M:0] den;
    logic ge;
    assign cur = chain[i*SW+:SW];
    assign rem = cur[RemLo+:M+2];
    assign den = cur[DenLo+:M+1];
    assign diff = rem - {1'b0, den};
    assign ge = rem >= {1'b0, den};
    assign nxt = {cur[SW-1:RemLo+M+2], (ge ? diff : rem) << 1, den, cur[N-2:0], ge};
    localparam int Regs = NSteps > 0 && fp_pkg::reg_after(i, NSteps, N) ? 1 : 0;
    fp_stage #(.W(SW), .N(Regs)) u_reg (.clk(clk), .d(nxt), .q(chain[(i+1)*SW+:SW]));
  end

  // ---- last stage: normalise, round, pack, special values (fp_finish) -------------------
  /* verilator lint_off UNUSEDSIGNAL */
  st_t l;  // the divisor is not needed any more
  /* verilator lint_on UNUSEDSIGNAL */
  assign l = chain[N*SW+:SW];
  fp_finish #(
      .E(E), .M(M), .SW(N), .XW(XW), .RNE(RNE), .FLUSH(FLUSH), .RMID(0), .ROUT(ROut)
  ) u_finish (
      .clk(clk),
      .nan(l.nan),
      .inf(l.inf),
      .inf_sign(l.sign),
      .zero(l.zero),
      .zero_sign(l.sign),
      .sign(l.sign),
      .exp(l.exp),
      .sig(l.q),
      .sticky_in(|l.rem),
      .y(y)
  );
  fp_valid #(.N(LAT)) u_valid (.clk(clk), .rst(rst), .d(in_valid), .q(out_valid));
endmodule
