// The thread machinery every DynRTP unit shares (paper section 3.1, Figure 2; units/cycle_unit.h,
// docs/cycle-model.md "Units"; D20, D25, D32), in the cycle model's order of a cycle:
//   1. deliver: the pipeline's front thread whose latency elapsed leaves on its path;
//   2. issue:   the issue slot takes the chained thread or the ready FIFO's front (threads in the
//               order their data arrived) and holds it for its request's steps; the unit's
//               datapath computes the step in this cycle (iss_*), the thread enters the pipeline
//               with its last step and leaves DEPTH cycles later;
//   3. receive: one cache response; its thread becomes ready when all its items arrived;
//   4. accept:  while no fetch is under way, the first input path (priority order, D25) with a
//               thread gives it up; the unit names the items to fetch (acc_first, acc_count), one
//               cache request per cycle goes out while the cache takes them (req_ready).
// What a stage writes is seen by the others in the next cycle (registers), as in the model: a
// thread pushed on a path in cycle c is accepted in c + 1 at the earliest, a thread made ready in
// c issues in c + 1 at the earliest. The input paths hold every thread (THREADS + 1 entries: a
// path is never full, units/dynrtp.cpp), as do the ready FIFO and the pipeline.
// The unit around it keeps the per-thread state its step needs; this module holds thread ids.
module unit_threads #(
    parameter int THREADS = 16,
    parameter int INPUTS  = 3,
    parameter int DEPTH   = 1,   // pipeline depth after the last step (>= 1)
    parameter int PW      = 8,   // payload bits the pipeline carries with a thread
    parameter int IW      = 32,  // cache item address bits
    parameter int CW      = 4,   // fetch count bits (items per request)
    parameter int SW      = 8,   // step count bits (issue cycles per request)
    parameter bit FAULT_PRIORITY_SWAP = 1'b0,  // tests only (rtl/lockstep_test.cpp)
    parameter int TW      = THREADS > 1 ? $clog2(THREADS) : 1
) (
    input  logic                     clk,
    input  logic                     rst,
    // Input paths in priority order (0 first): a thread pushed this cycle. Path i's thread is
    // in_thread[i*TW +: TW] (flat vectors, not packed arrays: yosys 0.23 reads no packed arrays).
    input  logic [INPUTS-1:0]        in_valid,
    input  logic [INPUTS*TW-1:0]     in_thread,
    // Accept: the thread taken from a path this cycle and the items it needs.
    output logic                     acc_valid,
    output logic [TW-1:0]            acc_thread,
    input  logic [IW-1:0]            acc_first,
    input  logic [CW-1:0]            acc_count,
    // Cache port: one request per cycle; responses tagged with the thread.
    output logic                     req_valid,
    output logic [IW-1:0]            req_item,
    output logic [TW-1:0]            req_thread,
    input  logic                     req_ready,
    input  logic                     resp_valid,
    input  logic [TW-1:0]            resp_thread,
    // Issue: the thread whose request starts this cycle; the unit answers with its steps, whether
    // its next request issues right behind it (a chain) and the payload it leaves with.
    output logic                     iss_valid,
    output logic [TW-1:0]            iss_thread,
    input  logic [SW-1:0]            iss_steps,
    input  logic                     iss_chain,
    input  logic [PW-1:0]            iss_payload,
    // Delivery on the path the payload names.
    output logic                     out_valid,
    output logic [TW-1:0]            out_thread,
    output logic [PW-1:0]            out_payload,
    input  logic                     out_ready
);
  // FIFOs of thread ids: 2^QB slots, pointers one bit wider (full and empty apart).
  localparam int QB = $clog2(THREADS + 1) < 1 ? 1 : $clog2(THREADS + 1);
  localparam int QS = 1 << QB;
  localparam int CTW = 32;  // the cycle counter and the pipeline's due cycles

  logic [CTW-1:0] now;

  // ---- input paths ----------------------------------------------------------------------------
  logic [TW-1:0] path_q[INPUTS][QS];
  logic [QB:0] path_head[INPUTS], path_tail[INPUTS];
  logic [INPUTS-1:0] path_any;
  localparam int SelW = INPUTS > 1 ? $clog2(INPUTS) : 1;  // path index bits
  logic [SelW-1:0] sel;
  always_comb begin
    sel = '0;
    for (int i = 0; i < INPUTS; i++) path_any[i] = path_head[i] != path_tail[i];
    for (int k = INPUTS - 1; k >= 0; k--) begin
      // The injected fault (tests only): the first two paths' priorities swapped.
      logic [SelW-1:0] path;
      path = FAULT_PRIORITY_SWAP && INPUTS > 1 && k < 2 ? SelW'(1 - k) : SelW'(k);
      if (path_any[path]) sel = path;
    end
  end

  // ---- fetch -----------------------------------------------------------------------------------
  logic fetching;
  logic [TW-1:0] fetch_thread;
  logic [IW-1:0] fetch_next;
  logic [CW-1:0] fetch_left;
  logic [CW-1:0] waiting[THREADS];

  assign acc_valid = !fetching && path_any != '0;
  assign acc_thread = path_q[sel][path_head[sel][QB-1:0]];
  assign req_valid = fetching || (acc_valid && acc_count != '0);
  assign req_item = fetching ? fetch_next : acc_first;
  assign req_thread = fetching ? fetch_thread : acc_thread;

  // ---- ready FIFO, issue slot ------------------------------------------------------------------
  logic [TW-1:0] ready_q[QS];
  logic [QB:0] ready_head, ready_tail;
  logic [SW-1:0] steps_left;
  logic chained;
  logic [TW-1:0] chain_thread;
  logic ready_any;
  assign ready_any = ready_head != ready_tail;
  assign iss_valid = steps_left == '0 && (chained || ready_any);
  assign iss_thread = chained ? chain_thread : ready_q[ready_head[QB-1:0]];
  logic [SW-1:0] steps;
  assign steps = iss_steps == '0 ? SW'(1) : iss_steps;

  logic got_ready, acc_ready;  // the response completes its thread; the accept fetches nothing
  assign got_ready = resp_valid && waiting[resp_thread] == CW'(1);
  assign acc_ready = acc_valid && acc_count == '0;

  // ---- pipeline --------------------------------------------------------------------------------
  logic [CTW-1:0] pipe_due[QS];
  logic [TW-1:0] pipe_thread[QS];
  logic [PW-1:0] pipe_payload[QS];
  logic [QB:0] pipe_head, pipe_tail;
  logic [CTW-1:0] due_delta;
  assign due_delta = now - pipe_due[pipe_head[QB-1:0]];
  assign out_valid = pipe_head != pipe_tail && !due_delta[CTW-1];
  assign out_thread = pipe_thread[pipe_head[QB-1:0]];
  assign out_payload = pipe_payload[pipe_head[QB-1:0]];

  always_ff @(posedge clk) begin
    if (rst) begin
      now <= '0;
      for (int i = 0; i < INPUTS; i++) begin
        path_head[i] <= '0;
        path_tail[i] <= '0;
      end
      fetching <= 1'b0;
      for (int t = 0; t < THREADS; t++) waiting[t] <= '0;
      ready_head <= '0;
      ready_tail <= '0;
      steps_left <= '0;
      chained <= 1'b0;
      pipe_head <= '0;
      pipe_tail <= '0;
    end else begin
      now <= now + 1;
      // 1. deliver
      if (out_valid && out_ready) pipe_head <= pipe_head + 1;
      // 2. issue
      if (iss_valid) begin
        if (!chained) ready_head <= ready_head + 1;
        steps_left <= steps - SW'(1);
        chained <= iss_chain;
        chain_thread <= iss_thread;
        if (!iss_chain) begin
          pipe_due[pipe_tail[QB-1:0]] <= now + CTW'(steps) - CTW'(1) + CTW'(DEPTH);
          pipe_thread[pipe_tail[QB-1:0]] <= iss_thread;
          pipe_payload[pipe_tail[QB-1:0]] <= iss_payload;
          pipe_tail <= pipe_tail + 1;
        end
      end else if (steps_left != '0) begin
        steps_left <= steps_left - SW'(1);
      end
      // 3. receive, then 4. accept: up to two threads made ready, in that order
      if (resp_valid) waiting[resp_thread] <= waiting[resp_thread] - CW'(1);
      if (got_ready) ready_q[ready_tail[QB-1:0]] <= resp_thread;
      if (acc_ready) ready_q[ready_tail[QB-1:0]+QB'(got_ready)] <= acc_thread;
      ready_tail <= ready_tail + (QB + 1)'(got_ready) + (QB + 1)'(acc_ready);
      // 4. accept
      if (acc_valid) begin
        path_head[sel] <= path_head[sel] + 1;
        if (acc_count != '0) begin
          waiting[acc_thread] <= acc_count;
          fetch_thread <= acc_thread;
          if (req_ready) begin
            fetching <= acc_count != CW'(1);
            fetch_next <= acc_first + IW'(1);
            fetch_left <= acc_count - CW'(1);
          end else begin
            fetching <= 1'b1;
            fetch_next <= acc_first;
            fetch_left <= acc_count;
          end
        end
      end else if (fetching && req_ready) begin
        fetching <= fetch_left != CW'(1);
        fetch_next <= fetch_next + IW'(1);
        fetch_left <= fetch_left - CW'(1);
      end
      // Threads arriving on the paths (taken from the next cycle on).
      for (int i = 0; i < INPUTS; i++)
        if (in_valid[i]) begin
          path_q[i][path_tail[i][QB-1:0]] <= in_thread[i*TW+:TW];
          path_tail[i] <= path_tail[i] + 1;
        end
    end
  end
endmodule
