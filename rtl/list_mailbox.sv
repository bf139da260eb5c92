// One thread's mailbox of the list unit (paper section 3.1: "omitting objects that have already
// been visited by the same ray"; units/mailbox.h; D28): the last N ids, each with the mask of the
// packet's rays that visited it, kept as a ring of `size` valid slots from `head` (the oldest),
// FIFO replacement when full. Combinational: the filter of one id and mask and the ring's next
// state; the list unit writes it back. N = 0: no mailbox, every ray visits every entry.
// FAULT_NEVER_HITS (tests only, rtl/lockstep_test.cpp): no id is ever found.
// Slot k is ids[k*32 +: 32] and masks[k*P +: P] (flat vectors: yosys 0.23 reads no array ports).
module list_mailbox #(
    parameter int N = 8,
    parameter int P = 4,
    parameter bit FAULT_NEVER_HITS = 1'b0,
    parameter int NB = N > 1 ? $clog2(N + 1) : 1,  // bits of a count 0..N
    parameter int SB = N > 1 ? $clog2(N) : 1,      // bits of a slot 0..N-1
    parameter int NS = N > 0 ? N : 1               // slots held (one unused without a mailbox)
) (
    input  logic [NS*32-1:0] ids,
    input  logic [NS*P-1:0] masks,
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
    assign unused = ^{ids, masks, id};
    /* verilator lint_on UNUSEDSIGNAL */
  end else begin : g_ring
    localparam int SpanW = NB + 1;
    logic hit;
    logic [SB-1:0] hit_slot, tail;
    always_comb begin
      int hd, sz;  // head and size as numbers
      hd = 32'(head);
      sz = 32'(size);
      hit = 1'b0;
      hit_slot = '0;
      for (int k = 0; k < N; k++) begin
        // Slot k is valid when its distance from the head is below the size.
        logic [NB:0] span;
        span = k >= hd ? SpanW'(k - hd) : SpanW'(k + N - hd);
        if (!FAULT_NEVER_HITS && span < {1'b0, size} && ids[k*32+:32] == id) begin
          hit = 1'b1;
          hit_slot = SB'(k);
        end
      end
      tail = hd + sz >= N ? SB'(hd + sz - N) : SB'(hd + sz);
      write = 1'b1;
      if (hit) begin
        todo = mask & ~masks[hit_slot*P+:P];
        slot = hit_slot;
        slot_mask = masks[hit_slot*P+:P] | mask;
        next_head = head;
        next_size = size;
      end else begin
        todo = mask;
        slot_mask = mask;
        if (sz < N) begin
          slot = tail;
          next_head = head;
          next_size = size + NB'(1);
        end else begin
          slot = head;
          next_head = hd + 1 == N ? '0 : head + SB'(1);
          next_size = size;
        end
      end
    end
  end
endmodule
