//! Runs a Cortex-M4F ELF in Unicorn and counts the instructions and cycles
//! of every call of its measured functions.
//!
//! The CPU is Unicorn's Cortex-M4 (ARMv7E-M with the FPv4-SP FPU; Unicorn
//! never traps FP instructions, so the reset handler's write of CPACR only
//! needs its page mapped). Memory: the ELF's loadable segments in the code
//! region, RAM from `0x2000_0000` up to the symbol `_stack_start` (the top
//! of RAM that `cortex-m-rt` puts the stack at), the System Control Space
//! page as plain memory. The emulation starts at the reset vector with the
//! vector table's stack pointer and ends at the program's semihosting exit
//! (`BKPT 0xAB`, `SYS_EXIT`), whose `SYS_OPEN` (`:tt`) and `SYS_WRITE`
//! (`SYS_WRITEC`, `SYS_WRITE0`) go to [`Emulation::output`].
//!
//! Counting: a block hook sees each translated block as it starts; each
//! block is decoded once with Capstone and timed instruction by instruction
//! ([`crate::timing`]). A call of a measured function starts when a block
//! starts at its entry and ends when a block starts at the return address
//! (its entry's LR) with the entry's stack pointer; every block in between
//! is counted, and when a block ending in a write to PC is followed by one
//! that does not start right after it, the branch was taken and costs the
//! refill `P`. Loads from the code region are counted by a memory hook over
//! it, in 32-bit words; instruction words are counted per block, a block
//! that continues the previous one sequentially not fetching its first word
//! again.

use std::collections::{HashMap, HashSet};

use capstone::Capstone;
use capstone::arch::arm::{ArchExtraMode, ArchMode};
use capstone::arch::{BuildsCapstone, BuildsCapstoneExtraMode};
use unicorn_engine::{
    Arch, ArmCpuModel, HookType, MemType, Mode, Prot, RegisterARM, Unicorn, uc_error,
};

use crate::elf::{CODE_REGION_END, Program};
use crate::timing::{Class, Costs, time};

/// The System Control Space page (CPACR at `0xE000_ED88`).
const SCS: u64 = 0xE000_E000;
/// Semihosting operations used.
const SYS_OPEN: u64 = 0x01;
const SYS_WRITEC: u64 = 0x03;
const SYS_WRITE0: u64 = 0x04;
const SYS_WRITE: u64 = 0x05;
const SYS_EXIT: u64 = 0x18;
/// `ADP_Stopped_ApplicationExit`: `SYS_EXIT`'s success.
const APPLICATION_EXIT: u64 = 0x20026;
/// The Thumb encoding of `BKPT 0xAB`.
const SEMIHOSTING_BKPT: u16 = 0xBEAB;

/// The counts of one call of a measured function (a tick).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Count {
    /// Instructions executed.
    pub instructions: u64,
    /// Cycles at zero wait states (taken-branch refills included).
    pub cycles: u64,
    /// Taken branches and other writes to PC followed elsewhere.
    pub taken: u64,
    /// 32-bit instruction words fetched from the code region.
    pub fetch_words: u64,
    /// 32-bit words loaded from the code region.
    pub flash_words: u64,
    /// Instructions per class ([`Class::ALL`] order).
    pub class_instructions: [u64; Class::ALL.len()],
    /// Cycles per class, zero wait states, refills in `Branch`.
    pub class_cycles: [u64; Class::ALL.len()],
}

impl Count {
    /// Cycles with `wait_states` on every word fetched or loaded from the
    /// code region.
    pub fn cycles_at(&self, wait_states: u32) -> u64 {
        self.cycles + u64::from(wait_states) * (self.fetch_words + self.flash_words)
    }
}

/// One decoded block.
#[derive(Clone, Debug)]
struct Block {
    count: Count,
    /// Whether its last instruction may write PC.
    writes_pc: bool,
    /// The address after its last instruction.
    fallthrough: u64,
    /// Its first and last instruction word (address / 4).
    first_word: u64,
    last_word: u64,
    /// The function it lies in ([`Program::function_of`]).
    function: usize,
}

/// A measured call in progress.
struct Call {
    return_to: u64,
    sp: u64,
    count: Count,
}

/// What a run of the program recorded: each measured call, in order, with
/// the cycles each function spent in it.
pub struct Emulation {
    /// The counts of every measured call.
    pub calls: Vec<Count>,
    /// For every measured call, the zero-wait-state cycles of each function
    /// it ran code of, `(function, cycles)`, by function index.
    pub call_functions: Vec<Vec<(usize, u64)>>,
    /// Everything the program wrote through semihosting.
    pub output: Vec<u8>,
    /// Indices into `calls` at which each output line starting with `run `
    /// was written, with the line.
    pub runs: Vec<(usize, String)>,
    /// Whether the program exited with success.
    pub success: bool,
}

struct State {
    cs: Capstone,
    costs: Costs,
    functions: usize,
    function_of: Box<dyn Fn(u64) -> usize>,
    entries: HashSet<u64>,
    blocks: HashMap<(u64, u32), Block>,
    call: Option<Call>,
    call_function_cycles: Vec<u64>,
    /// The previous block counted: its `writes_pc`, fallthrough, last word
    /// and function.
    previous: Option<(bool, u64, u64, usize)>,
    line: Vec<u8>,
    result: Emulation,
    exited: bool,
    error: Option<String>,
}

/// Runs `program` to its semihosting exit, counting the calls of the
/// functions at `entries` (Thumb addresses, the low bit ignored).
pub fn run(program: &Program, entries: &[u64], costs: Costs) -> Result<Emulation, String> {
    let cs = Capstone::new()
        .arm()
        .mode(ArchMode::Thumb)
        .extra_mode([ArchExtraMode::MClass].into_iter())
        .detail(true)
        .build()
        .map_err(|e| format!("capstone: {e}"))?;
    let functions = program.function_count();
    let function_of = {
        let p = program.function_starts();
        Box::new(move |addr: u64| match p.binary_search(&addr) {
            Ok(i) => i,
            Err(0) => 0,
            Err(i) => i - 1,
        })
    };
    let state = State {
        cs,
        costs,
        functions,
        function_of,
        entries: entries.iter().map(|e| e & !1).collect(),
        blocks: HashMap::new(),
        call: None,
        call_function_cycles: vec![0; functions + 1],
        previous: None,
        line: Vec::new(),
        result: Emulation {
            calls: Vec::new(),
            call_functions: Vec::new(),
            output: Vec::new(),
            runs: Vec::new(),
            success: false,
        },
        exited: false,
        error: None,
    };
    let uc_err = |what: &'static str| move |e: uc_error| format!("unicorn: {what}: {e:?}");
    let mut uc = Unicorn::new_with_data(Arch::ARM, Mode::THUMB, state).map_err(uc_err("new"))?;
    uc.ctl_set_cpu_model(ArmCpuModel::CORTEX_M4 as i32)
        .map_err(uc_err("cpu model"))?;
    for (start, size) in program.regions() {
        uc.mem_map(start, size, Prot::ALL).map_err(uc_err("map"))?;
    }
    uc.mem_map(SCS, 0x1000, Prot::ALL)
        .map_err(uc_err("map SCS"))?;
    for (address, bytes) in program.loads() {
        uc.mem_write(address, bytes).map_err(uc_err("load"))?;
    }
    let (sp, reset) = program.reset()?;
    uc.reg_write(RegisterARM::SP, sp).map_err(uc_err("SP"))?;
    uc.add_block_hook(1, 0, on_block)
        .map_err(uc_err("block hook"))?;
    uc.add_mem_hook(HookType::MEM_READ, 0, CODE_REGION_END - 1, on_flash_read)
        .map_err(uc_err("memory hook"))?;
    uc.add_intr_hook(on_interrupt)
        .map_err(uc_err("interrupt hook"))?;
    let started = uc.emu_start(reset | 1, u64::MAX, 0, 0);
    let state = uc.get_data_mut();
    if let Some(e) = state.error.take() {
        return Err(e);
    }
    if let Err(e) = started {
        let pc = uc.pc_read().unwrap_or(0);
        return Err(format!("unicorn stopped at {pc:#010x}: {e:?}"));
    }
    let state = uc.get_data_mut();
    if !state.exited {
        return Err("the program stopped without a semihosting exit".into());
    }
    Ok(std::mem::replace(
        &mut state.result,
        Emulation {
            calls: Vec::new(),
            call_functions: Vec::new(),
            output: Vec::new(),
            runs: Vec::new(),
            success: false,
        },
    ))
}

fn on_block(uc: &mut Unicorn<'_, State>, address: u64, size: u32) {
    let state = uc.get_data();
    let starting = state.call.is_none() && state.entries.contains(&address);
    let (lr, sp) = if starting || state.call.is_some() {
        (
            uc.reg_read(RegisterARM::LR).unwrap_or(0),
            uc.reg_read(RegisterARM::SP).unwrap_or(0),
        )
    } else {
        (0, 0)
    };
    let state = uc.get_data_mut();
    if let Some(call) = &mut state.call {
        // The previous block's last instruction went elsewhere: taken.
        if let Some((true, fallthrough, _, function)) = state.previous
            && fallthrough != address
        {
            let refill = u64::from(state.costs.refill);
            call.count.cycles += refill;
            call.count.class_cycles[Class::Branch.index()] += refill;
            call.count.taken += 1;
            if let Some(c) = state.call_function_cycles.get_mut(function) {
                *c += refill;
            }
        }
        if address == call.return_to && sp == call.sp {
            finish_call(state);
            return;
        }
    } else if starting {
        state.call = Some(Call {
            return_to: lr & !1,
            sp,
            count: Count::default(),
        });
        state.previous = None;
    } else {
        return;
    }
    if !state.blocks.contains_key(&(address, size)) {
        let mut code = vec![0u8; size as usize];
        if uc.mem_read(address, &mut code).is_err() {
            let state = uc.get_data_mut();
            state.error = Some(format!("block at {address:#010x}: unreadable"));
            let _ = uc.emu_stop();
            return;
        }
        let state = uc.get_data_mut();
        let block = decode(state, address, &code);
        state.blocks.insert((address, size), block);
    }
    let state = uc.get_data_mut();
    let Some(block) = state.blocks.get(&(address, size)) else {
        return;
    };
    let Some(call) = &mut state.call else {
        return;
    };
    add(&mut call.count, &block.count);
    // A block continuing the previous one sequentially does not fetch its
    // first word again.
    if let Some((_, _, last_word, _)) = state.previous
        && last_word == block.first_word
    {
        call.count.fetch_words -= 1;
    }
    if let Some(c) = state.call_function_cycles.get_mut(block.function) {
        *c += block.count.cycles;
    }
    state.previous = Some((
        block.writes_pc,
        block.fallthrough,
        block.last_word,
        block.function,
    ));
}

/// Ends the measured call: its counts and per-function cycles recorded.
fn finish_call(state: &mut State) {
    let Some(call) = state.call.take() else {
        return;
    };
    let functions: Vec<(usize, u64)> = state
        .call_function_cycles
        .iter_mut()
        .enumerate()
        .filter(|(_, c)| **c > 0)
        .map(|(f, c)| (f, std::mem::take(c)))
        .collect();
    state.result.calls.push(call.count);
    state.result.call_functions.push(functions);
    state.previous = None;
}

fn add(to: &mut Count, block: &Count) {
    to.instructions += block.instructions;
    to.cycles += block.cycles;
    to.fetch_words += block.fetch_words;
    for (t, b) in to
        .class_instructions
        .iter_mut()
        .zip(&block.class_instructions)
    {
        *t += b;
    }
    for (t, b) in to.class_cycles.iter_mut().zip(&block.class_cycles) {
        *t += b;
    }
}

/// Decodes and times the block of `code` at `address`.
fn decode(state: &State, address: u64, code: &[u8]) -> Block {
    let mut count = Count::default();
    let mut writes_pc = false;
    let mut end = address;
    if let Ok(insns) = state.cs.disasm_all(code, address) {
        for insn in insns.iter() {
            let timed = time(&state.cs, insn, &state.costs);
            count.instructions += 1;
            count.cycles += u64::from(timed.cycles);
            count.class_instructions[timed.class.index()] += 1;
            count.class_cycles[timed.class.index()] += u64::from(timed.cycles);
            writes_pc = timed.writes_pc;
            end = insn.address() + insn.bytes().len() as u64;
        }
    }
    let first_word = address / 4;
    let last_word = end.saturating_sub(1) / 4;
    count.fetch_words = last_word + 1 - first_word;
    Block {
        count,
        writes_pc,
        fallthrough: end,
        first_word,
        last_word,
        function: (state.function_of)(address).min(state.functions),
    }
}

fn on_flash_read(
    uc: &mut Unicorn<'_, State>,
    _kind: MemType,
    address: u64,
    size: usize,
    _value: i64,
) -> bool {
    if let Some(call) = &mut uc.get_data_mut().call {
        // The 32-bit words the access touches.
        let first = address / 4;
        let last = (address + size.max(1) as u64 - 1) / 4;
        call.count.flash_words += last + 1 - first;
    }
    true
}

/// Semihosting (`BKPT 0xAB`): the operation in r0, its argument in r1.
fn on_interrupt(uc: &mut Unicorn<'_, State>, _number: u32) {
    let pc = uc.pc_read().unwrap_or(0) & !1;
    let mut insn = [0u8; 2];
    let is_semihosting =
        uc.mem_read(pc, &mut insn).is_ok() && u16::from_le_bytes(insn) == SEMIHOSTING_BKPT;
    if !is_semihosting {
        uc.get_data_mut().error = Some(format!("exception at {pc:#010x} (not semihosting)"));
        let _ = uc.emu_stop();
        return;
    }
    let op = uc.reg_read(RegisterARM::R0).unwrap_or(0);
    let arg = uc.reg_read(RegisterARM::R1).unwrap_or(0);
    let word = |uc: &Unicorn<'_, State>, at: u64| {
        let mut w = [0u8; 4];
        uc.mem_read(at, &mut w)
            .map(|()| u64::from(u32::from_le_bytes(w)))
    };
    let result: Result<u64, String> = match op {
        // Any name opens the host's standard output (`:tt`).
        SYS_OPEN => Ok(1),
        SYS_WRITEC => uc
            .mem_read_as_vec(arg, 1)
            .map(|b| {
                emit(uc.get_data_mut(), &b);
                0
            })
            .map_err(|e| format!("{e:?}")),
        SYS_WRITE0 => {
            let mut bytes = Vec::new();
            let mut at = arg;
            while let Ok(b) = uc.mem_read_as_vec(at, 1) {
                if b[0] == 0 {
                    break;
                }
                bytes.push(b[0]);
                at += 1;
            }
            emit(uc.get_data_mut(), &bytes);
            Ok(0)
        }
        SYS_WRITE => (|| {
            let ptr = word(uc, arg + 4)?;
            let len = word(uc, arg + 8)?;
            let bytes = uc.mem_read_as_vec(ptr, len as usize)?;
            emit(uc.get_data_mut(), &bytes);
            Ok(0)
        })()
        .map_err(|e: uc_error| format!("{e:?}")),
        SYS_EXIT => {
            let state = uc.get_data_mut();
            state.exited = true;
            state.result.success = arg == APPLICATION_EXIT;
            let _ = uc.emu_stop();
            Ok(0)
        }
        other => Err(format!("semihosting operation {other:#x} not supported")),
    };
    match result {
        Ok(r0) => {
            let _ = uc.reg_write(RegisterARM::R0, r0);
            let _ = uc.reg_write(RegisterARM::PC, (pc + 2) | 1);
        }
        Err(e) => {
            uc.get_data_mut().error = Some(format!("semihosting at {pc:#010x}: {e}"));
            let _ = uc.emu_stop();
        }
    }
}

/// Appends `bytes` to the output, noting each `run ` line.
fn emit(state: &mut State, bytes: &[u8]) {
    state.result.output.extend_from_slice(bytes);
    for &b in bytes {
        if b == b'\n' {
            let line = String::from_utf8_lossy(&state.line).into_owned();
            if line.starts_with("run ") {
                state.result.runs.push((state.result.calls.len(), line));
            }
            state.line.clear();
        } else {
            state.line.push(b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elf::Program;

    /// A program counted by hand, from `arm-none-eabi-as` (cortex-m4,
    /// fpv4-sp-d16): the reset handler calls `measured` twice, then exits
    /// through semihosting:
    ///
    /// ```text
    /// 40: f000 f81e  bl measured            68: (after the calls)
    /// 44: f000 f81c  bl measured
    /// 48: 2018       movs r0, #0x18          SYS_EXIT
    /// 4a: 4901       ldr r1, [pc, #4]        0x20026, application exit
    /// 4c: beab       bkpt 0xab
    /// 80: b510       push {r4, lr}           1 + 2               3
    /// 82: 2403       movs r4, #3                                 1
    /// 84: 3c01       subs r4, #1             × 3                 3
    /// 86: ee30 0a20  vadd.f32 s0, s0, s1     × 3                 3
    /// 8a: d1fb       bne 84                  × 3, taken twice    3 + 2P
    /// 8c: 4802       ldr r0, [pc, #8]        a literal in flash  2
    /// 8e: fbb0 f0f0  udiv r0, r0, r0                             12
    /// 92: ee80 1a20  vdiv.f32 s2, s0, s1                         14
    /// 96: bd10       pop {r4, pc}            1 + 2, taken        3 + P
    /// ```
    ///
    /// 15 instructions and 44 + 3P = 53 cycles per call at P = 3; its
    /// blocks fetch the words of 0x80-0x8b (3), 0x84-0x8b twice (2 each),
    /// then 0x8c-0x97 (3): 10 words, and load one word (the literal) from
    /// flash, so at `W` wait states 53 + 11 W.
    #[test]
    fn a_hand_counted_program_counts_exactly() {
        let code: &[(u64, &[u16])] = &[
            (
                0x40,
                &[0xf000, 0xf81e, 0xf000, 0xf81c, 0x2018, 0x4901, 0xbeab],
            ),
            (0x50, &[0x0026, 0x0002]),
            (
                0x80,
                &[
                    0xb510, 0x2403, 0x3c01, 0xee30, 0x0a20, 0xd1fb, 0x4802, 0xfbb0, 0xf0f0, 0xee80,
                    0x1a20, 0xbd10,
                ],
            ),
            (0x98, &[0x0007, 0x0000]),
        ];
        let mut image = vec![0u8; 0x9c];
        image[..8].copy_from_slice(&[0x00, 0x10, 0x00, 0x20, 0x41, 0, 0, 0]);
        for (at, halfwords) in code {
            for (i, h) in halfwords.iter().enumerate() {
                let a = *at as usize + 2 * i;
                image[a..a + 2].copy_from_slice(&h.to_le_bytes());
            }
        }
        let program = Program::from_image(
            image,
            0x2000_1000,
            vec![(0x40, "reset".into()), (0x80, "measured".into())],
        );
        let costs = Costs {
            refill: 3,
            divide: 12,
            wait_states: 5,
        };
        let run = run(&program, &program.entries("measured"), costs).unwrap();
        assert!(run.success);
        assert_eq!(run.calls.len(), 2);
        for call in &run.calls {
            assert_eq!(call.instructions, 15);
            assert_eq!(call.cycles, 53);
            assert_eq!(call.taken, 3);
            assert_eq!(call.fetch_words, 10);
            assert_eq!(call.flash_words, 1);
            assert_eq!(call.cycles_at(5), 53 + 5 * 11);
            let by_class = |c: Class| {
                (
                    call.class_instructions[c.index()],
                    call.class_cycles[c.index()],
                )
            };
            assert_eq!(by_class(Class::Multiple), (2, 6));
            assert_eq!(by_class(Class::Alu), (4, 4));
            assert_eq!(by_class(Class::FpAlu), (3, 3));
            // The refills of the two taken `bne` and of the `pop` into PC.
            assert_eq!(by_class(Class::Branch), (3, 3 + 3 * 3));
            assert_eq!(by_class(Class::Load), (1, 2));
            assert_eq!(by_class(Class::Divide), (1, 12));
            assert_eq!(by_class(Class::FpDivide), (1, 14));
        }
        // Every cycle is the measured function's.
        assert_eq!(run.call_functions[0], vec![(1, 53)]);
    }
}
