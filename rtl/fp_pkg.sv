// Shared constants and helpers of the parameterised float operators (docs/rtl.md). A format is
// Float<E, M> of fixedfloat/: 1 sign bit, E exponent bits (bias 2^(E-1)-1), M stored mantissa bits.
package fp_pkg;

  // Width of the signed exponent arithmetic inside the operators: holds a product's exponent
  // (up to 2^(E+1)), a quotient's (down to -(2^E + M) after pre-normalising subnormals) and a
  // leading-zero count of a 2M+2-bit significand.
  function automatic int xw(input int e, input int m);
    xw = (e + 3 > $clog2(2 * m + 3) + 3) ? e + 3 : $clog2(2 * m + 3) + 3;
  endfunction

  // Pipeline placement: with `regs` registers spread over `steps` equal steps, whether a register
  // follows step i (0-based). Exactly `regs` of the steps get one (regs <= steps), the last always.
  function automatic bit reg_after(input int i, input int regs, input int steps);
    reg_after = ((i + 1) * regs / steps) != (i * regs / steps);
  endfunction

endpackage
