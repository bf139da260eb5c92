// The comparator of Float<E, M> (combinational), as fixedfloat's lt, le, eq: false when either
// side is NaN, -0 == +0, and in flush mode a subnormal compares as a zero. One magnitude
// comparator and the sign logic; also the operands as a comparator/multiplexer passes them on
// (a subnormal flushed to a signed zero in flush mode, anything else unchanged, NaN included).
module fp_cmp_core #(
    parameter int E     = 7,
    parameter int M     = 16,
    parameter bit FLUSH = 1'b1
) (
    input  logic [E+M:0] a,
    input  logic [E+M:0] b,
    output logic         lt,
    output logic         eq,
    output logic [E+M:0] fa,
    output logic [E+M:0] fb
);
  logic sa, sb, na, nb;
  logic [E+M-1:0] ma, mb;
  /* verilator lint_off UNUSEDSIGNAL */
  logic ia, ib, za, zb;
  logic [E-1:0] ea, eb;
  logic [M:0] ga, gb;
  /* verilator lint_on UNUSEDSIGNAL */

  fp_class #(.E(E), .M(M), .FLUSH(FLUSH)) u_ca (
      .x(a), .sign(sa), .nan(na), .inf(ia), .zero(za), .exp(ea), .sig(ga), .mag(ma)
  );
  fp_class #(.E(E), .M(M), .FLUSH(FLUSH)) u_cb (
      .x(b), .sign(sb), .nan(nb), .inf(ib), .zero(zb), .exp(eb), .sig(gb), .mag(mb)
  );

  logic mlt, meq, zeros;
  assign mlt   = ma < mb;
  assign meq   = ma == mb;
  assign zeros = ~(|ma) & ~(|mb);
  // Different signs: a < b iff a is the negative one (two zeros are equal); equal signs: the
  // magnitudes decide, reversed for negative operands.
  assign lt    = ~(na | nb) & ~zeros & ((sa ^ sb) ? sa : (sa ? ~(mlt | meq) : mlt));
  assign eq    = ~(na | nb) & (zeros | (meq & ~(sa ^ sb)));
  assign fa    = {sa, ma};
  assign fb    = {sb, mb};
endmodule
