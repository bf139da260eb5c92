// Decodes one encoding of Float<E, M> the way every operator reads it (docs/fixedfloat.md): the
// exponent all ones is inf (mantissa 0) or NaN; in flush mode (FLUSH = 1) a subnormal reads as a
// zero of the same sign.
module fp_class #(
    parameter int E     = 7,
    parameter int M     = 16,
    parameter bit FLUSH = 1'b1
) (
    input  logic [E+M:0] x,
    output logic         sign,
    output logic         nan,
    output logic         inf,
    output logic         zero,     // +-0, or a subnormal in flush mode
    output logic [E-1:0] exp,      // biased exponent; 1 for subnormals and zeros
    output logic [  M:0] sig,      // significand with the hidden bit; 0 for zeros
    output logic [E+M-1:0] mag     // the magnitude bits, 0 for a flushed subnormal
);
  logic [E-1:0] ef;
  logic [M-1:0] mf;
  logic         sub;
  assign ef      = x[E+M-1:M];
  assign mf      = x[M-1:0];
  assign sign    = x[E+M];
  assign nan     = (&ef) & (|mf);
  assign inf     = (&ef) & ~(|mf);
  assign sub     = ~(|ef) & (|mf);
  assign zero    = ~(|ef) & (~(|mf) | FLUSH);
  assign exp     = (|ef) ? ef : E'(1);
  assign sig     = zero ? '0 : {|ef, mf};
  assign mag     = (FLUSH && sub) ? '0 : x[E+M-1:0];
endmodule
