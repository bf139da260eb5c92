// The float operators' common tail, as SoftFloat's one round-and-pack: the exact result
//   sig * 2^(exp - bias - (SW-1)), plus something below sig's last bit when sticky_in is set,
// normalised (fp_normalize), RMID register stages, then rounded and packed (fp_round) with the
// special values overriding it, then ROUT register stages to y. fp_add, fp_mul and fp_div each end
// in one fp_finish; their LAT parameters place its two register groups (fp_add, fp_mul: RMID is
// their stage-2 boundary; fp_div rounds in the stage it normalises, RMID = 0).
//   nan:  the default NaN (sign clear, quiet bit set)
//   inf:  +-inf with inf_sign
//   zero: an exact zero with zero_sign
//   else: the rounded result with sign
module fp_finish #(
    parameter int E     = 7,
    parameter int M     = 16,
    parameter int SW    = M + 3,  // width of sig, at least M + 3
    parameter int XW    = fp_pkg::xw(E, M),
    parameter bit RNE   = 1'b1,
    parameter bit FLUSH = 1'b1,
    parameter int RMID  = 0,      // register stages between normalising and rounding
    parameter int ROUT  = 0       // register stages after the result
) (
    input  logic          clk,
    input  logic          nan,
    input  logic          inf,
    input  logic          inf_sign,
    input  logic          zero,
    input  logic          zero_sign,
    input  logic          sign,
    input  logic [XW-1:0] exp,
    input  logic [SW-1:0] sig,
    input  logic          sticky_in,
    output logic [ E+M:0] y
);
  localparam logic [E+M-1:0] NanMag = {{E{1'b1}}, 1'b1, {(M - 1) {1'b0}}};
  localparam logic [E+M-1:0] InfMag = {{E{1'b1}}, {M{1'b0}}};

  typedef struct packed {
    logic nan;
    logic inf;
    logic inf_sign;
    logic zero;
    logic zero_sign;
    logic sign;
    logic [XW-1:0] e;
    logic [M:0] kept;
    logic guard;
    logic sticky;
  } norm_t;

  // ---- normalise ---------------------------------------------------------------------------
  norm_t n, n_q;
  logic [XW-1:0] n_e;
  logic [M:0] n_kept;
  logic n_guard, n_sticky;
  fp_normalize #(.E(E), .M(M), .SW(SW), .XW(XW)) u_norm (
      .exp(exp),
      .sig(sig),
      .sticky_in(sticky_in),
      .e(n_e),
      .kept(n_kept),
      .guard(n_guard),
      .sticky(n_sticky)
  );

  always_comb begin
    n.nan = nan;
    n.inf = inf;
    n.inf_sign = inf_sign;
    n.zero = zero;
    n.zero_sign = zero_sign;
    n.sign = sign;
    n.e = n_e;
    n.kept = n_kept;
    n.guard = n_guard;
    n.sticky = n_sticky;
  end

  fp_stage #(.W($bits(n)), .N(RMID)) u_rmid (.clk(clk), .d(n), .q(n_q));

  // ---- round, pack, special values ---------------------------------------------------------
  logic [E+M:0] rounded, result;
  fp_round #(.E(E), .M(M), .RNE(RNE), .FLUSH(FLUSH), .XW(XW)) u_round (
      .sign(n_q.sign),
      .e(n_q.e),
      .kept(n_q.kept),
      .guard(n_q.guard),
      .sticky(n_q.sticky),
      .y(rounded)
  );

  always_comb begin
    if (n_q.nan) result = {1'b0, NanMag};
    else if (n_q.inf) result = {n_q.inf_sign, InfMag};
    else if (n_q.zero) result = {n_q.zero_sign, {(E + M) {1'b0}}};
    else result = rounded;
  end

  fp_stage #(.W(E + M + 1), .N(ROUT)) u_rout (.clk(clk), .d(result), .q(y));
endmodule
