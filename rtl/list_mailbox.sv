// One thread's mailbox of the list unit (paper section 3.1: "omitting objects that have already
// been visited by the same ray"; units/mailbox.h; D28): the last N ids, each with the mask of the
// packet's rays that visited it, kept as a ring of `size` valid slots from `head` (the oldest),
// FIFO replacement when full. Combinational: the filter of one id and mask and the ring's next
// state; the list unit writes it back. N = 0: no mailbox, every ray visits every entry.
// FAULT_NEVER_HITS (tests only, rtl/lockstep_test.cpp): no id is ever found.
module list_mailbox #(
    parameter int N = 8,
    parameter int P = 4,
    parameter bit FAULT_NEVER_HITS = 1'b0,
    parameter int NB = N > 1 ? $clog2(N + 1) : 1,  // bits of a count 0..N
    parameter int SB = N > 1 ? $clog2(N) : 1       // bits of a slot 0..N-1
) (
    input  logic [31:0]  ids  [N > 0 ? N : 1],
    input  logic [P-1:0] masks[N > 0 ? N : 1],
    input  logic [SB-1:0] head,
    input  logic [NB-1:0] size,
    input  logic [31:0]  id,
    input  logic [P-1:0] mask,
    output logic [P-1:0] todo,     // the rays of `mask` that still have to visit `id`
    output logic [SB-1:0] slot,    // the slot written: the hit, or the new entry's
    output logic [P-1:0] slot_mask,
    output logic [SB-1:0] next_head,
    output logic [NB-1:0] next_size,
    output logic          write    // false only without a mailbox
);
  if (N == 0) begin : g_none
    assign todo = mask;
    assign slot = '0;
    assign slot_mask = '0;
    assign next_head = head;
    assign next_size = size;
    assign write = 1'b0;
    /* verilator lint_off UNUSEDSIGNAL */
    logic unused;
    assign unused = ^{ids[0], masks[0], id};
    /* verilator lint_on UNUSEDSIGNAL */
  end else begin : g_ring
    logic hit;
    logic [SB-1:0] hit_slot, tail;
    always_comb begin
      hit = 1'b0;
      hit_slot = '0;
      for (int k = 0; k < N; ++k) begin
        // Slot k is valid when its distance from the head is below the size.
        logic [NB:0] span;
        span = k >= int'(head) ? (NB + 1)'(k - int'(head)) : (NB + 1)'(k + N - int'(head));
        if (!FAULT_NEVER_HITS && span < {1'b0, size} && ids[k] == id) begin
          hit = 1'b1;
          hit_slot = SB'(k);
        end
      end
      tail = int'(head) + int'(size) >= N ? SB'(int'(head) + int'(size) - N)
                                           : SB'(int'(head) + int'(size));
      write = 1'b1;
      if (hit) begin
        todo = mask & ~masks[hit_slot];
        slot = hit_slot;
        slot_mask = masks[hit_slot] | mask;
        next_head = head;
        next_size = size;
      end else begin
        todo = mask;
        slot_mask = mask;
        if (int'(size) < N) begin
          slot = tail;
          next_head = head;
          next_size = size + NB'(1);
        end else begin
          slot = head;
          next_head = int'(head) + 1 == N ? '0 : head + SB'(1);
          next_size = size;
        end
      end
    end
  end
endmodule
