// Normalisation before rounding (combinational). The exact result is
//   sig * 2^(exp - bias - (SW-1)),  plus something below sig's last bit when sticky_in is set,
// i.e. exp is the biased exponent the result has if sig's top bit is set. sig is shifted left
// over its leading zeros, but never below the smallest normal exponent (field 1); a result below
// it (exp < 1) is shifted right into the subnormal position with the shifted-out bits in sticky,
// so rounding happens on the subnormal grid as IEEE 754 gradual underflow asks (flush mode then
// zeroes a subnormal *after* rounding, fp_round). Out: e >= 1 and the M+1 bits kept (hidden bit
// first; a hidden bit of 0 means subnormal, e = 1), the guard bit and the sticky bit.
module fp_normalize #(
    parameter int E  = 7,
    parameter int M  = 16,
    parameter int SW = M + 3,  // at least M + 3
    parameter int XW = fp_pkg::xw(E, M)
) (
    input  logic signed [XW-1:0] exp,
    input  logic        [SW-1:0] sig,
    input  logic                 sticky_in,
    output logic        [XW-1:0] e,
    output logic        [   M:0] kept,
    output logic                 guard,
    output logic                 sticky
);
  localparam int CW = $clog2(SW + 1);
  localparam logic signed [XW-1:0] One = XW'(1);

  logic        [CW-1:0] lz;
  logic signed [XW-1:0] lz_s;
  logic        [SW-1:0] s;
  logic                 lost;
  logic        [XW-1:0] amount;

  fp_lzc #(.W(SW)) u_lzc (
      .x(sig),
      .n(lz)
  );

  always_comb begin
    lz_s = XW'(lz);
    lost = 1'b0;
    if (exp > lz_s) begin
      amount = XW'(lz);
      s      = sig << amount;
      e      = XW'(exp - lz_s);
    end else if (exp >= One) begin
      amount = XW'(exp - One);
      s      = sig << amount;
      e      = XW'(One);
    end else begin
      amount = XW'(One - exp);
      s      = sig >> amount;
      lost   = |(sig & ~({SW{1'b1}} << amount));
      e      = XW'(One);
    end
  end

  assign kept   = s[SW-1-:M+1];
  assign guard  = s[SW-2-M];
  assign sticky = (|s[SW-3-M:0]) | sticky_in | lost;
endmodule
