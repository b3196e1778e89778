//! The Cortex-M4 timing table: each Thumb-2 or FPv4-SP instruction's class
//! and cycles at zero wait states.
//!
//! Source: ARM Cortex-M4 Processor Technical Reference Manual, revision
//! r0p1 (ARM DDI 0439B / 100166_0001_00), §3.3 "Processor instruction
//! timings" (table 3-1, "Cortex-M4 instruction set summary") and §7.2.3
//! "FPU instruction set" (table 7-1, the FPU's cycle counts), as reprinted
//! in vendors' manuals (TI SWCU192 tables 3-25 and 3-27). The table's
//! cycles, with `P` the pipeline refill (1 to 3 cycles "depending on the
//! alignment and width of the target instruction, and whether the processor
//! manages to speculate the address early") and `N` the registers moved:
//!
//! | class | instructions | cycles |
//! |---|---|---|
//! | ALU | data processing, shifts, compares, moves, extends, bit fields, saturation, `IT`, `NOP` | 1 (to PC: 1 + P) |
//! | multiply | `MUL`, `MLA`, `MLS`, `SMULL`, `UMULL`, `SMLAL`, `UMLAL`, the DSP multiplies | 1 |
//! | divide | `SDIV`, `UDIV` | 2 to 12 by the operands: counted 12 |
//! | load | `LDR`, `LDRB`, `LDRH`, `LDRSB`, `LDRSH`, `LDREX*` | 2 (to PC: 2 + P) |
//! | load pair | `LDRD` | 3 |
//! | store | `STR`, `STRB`, `STRH`, `STREX*` | 2 |
//! | store pair | `STRD` | 3 |
//! | load multiple | `LDM`, `POP` | 1 + N (with PC: 1 + N + P) |
//! | store multiple | `STM`, `PUSH` | 1 + N |
//! | branch | `B`, `BL`, `BX`, `BLX`, `CBZ`, `CBNZ` | 1, + P when taken |
//! | table branch | `TBB`, `TBH` | 2 + P |
//! | FP ALU | `VADD`, `VSUB`, `VMUL`, `VNMUL`, `VABS`, `VNEG`, `VCMP`, `VCVT`, `VMOV` (immediate, S to S, half of D), `VMRS`, `VMSR` | 1 |
//! | FP MAC | `VMLA`, `VMLS`, `VNMLA`, `VNMLS`, `VFMA`, `VFMS`, `VFNMA`, `VFNMS` | 3 |
//! | FP divide | `VDIV`, `VSQRT` | 14 |
//! | FP move | `VMOV` between one S and one core register, or two of each | 2 |
//! | FP load/store | `VLDR`, `VSTR` | 2 (.32), 3 (.64) |
//! | FP load/store multiple | `VLDM`, `VSTM`, `VPUSH`, `VPOP` | 1 + N (S), 1 + 2N (D) |
//!
//! Choices where the table gives a range or depends on timing this model
//! does not follow (each gives the upper end, so the counts bound the core's):
//! a divide costs 12; a taken branch or a write to PC costs `P` = 3 by
//! default ([`Costs::refill`]); neighbouring single loads and stores are not
//! pipelined (the TRM lets the second complete in one cycle); an
//! instruction of an IT block whose condition fails costs as if executed (the
//! core spends one cycle on it). Unlisted instructions cost 1.
//!
//! Flash wait states ([`Costs::wait_states`] `W`) are not in the table: a
//! memory of `W` wait states adds `W` cycles to each 32-bit instruction word
//! fetched from it (the core fetches 32 bits at a time; a word is fetched
//! again after a taken branch) and to each 32-bit word loaded from it. The
//! emulator applies them to the Cortex-M code region (below `0x2000_0000`,
//! where the program and its tables are), never to RAM: a part without a
//! flash cache or prefetch buffer. Vendors' accelerators (an instruction
//! cache, prefetch) hide most of them; the zero-wait-state figure is the
//! core's.

use capstone::arch::ArchOperand;
use capstone::arch::arm::{ArmInsn, ArmOperandType};
use capstone::{Capstone, Insn};

/// The classes of the table (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Class {
    /// Data processing, 1 cycle.
    Alu,
    /// Integer multiply, 1 cycle.
    Multiply,
    /// Integer divide, 12 cycles counted.
    Divide,
    /// Single load, 2 cycles.
    Load,
    /// Single store, 2 cycles.
    Store,
    /// `LDRD`, `STRD`, 3 cycles.
    Pair,
    /// `LDM`, `STM`, `PUSH`, `POP`: 1 + N.
    Multiple,
    /// Branches: 1, + P when taken.
    Branch,
    /// `TBB`, `TBH`: 2 + P.
    TableBranch,
    /// FP arithmetic and moves within the FPU, 1 cycle.
    FpAlu,
    /// FP multiply-accumulate, 3 cycles.
    FpMac,
    /// `VDIV`, `VSQRT`, 14 cycles.
    FpDivide,
    /// `VMOV` between core and FP registers, 2 cycles.
    FpMove,
    /// `VLDR`, `VSTR`: 2 or 3.
    FpLoadStore,
    /// `VLDM`, `VSTM`, `VPUSH`, `VPOP`: 1 + N or 1 + 2N.
    FpMultiple,
}

impl Class {
    /// Every class, in report order.
    pub const ALL: [Class; 15] = [
        Class::Alu,
        Class::Multiply,
        Class::Divide,
        Class::Load,
        Class::Store,
        Class::Pair,
        Class::Multiple,
        Class::Branch,
        Class::TableBranch,
        Class::FpAlu,
        Class::FpMac,
        Class::FpDivide,
        Class::FpMove,
        Class::FpLoadStore,
        Class::FpMultiple,
    ];

    /// The class's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Class::Alu => "alu",
            Class::Multiply => "multiply",
            Class::Divide => "divide",
            Class::Load => "load",
            Class::Store => "store",
            Class::Pair => "ldrd/strd",
            Class::Multiple => "ldm/stm/push/pop",
            Class::Branch => "branch",
            Class::TableBranch => "tbb/tbh",
            Class::FpAlu => "fp alu",
            Class::FpMac => "fp mac",
            Class::FpDivide => "fp div/sqrt",
            Class::FpMove => "fp<->core move",
            Class::FpLoadStore => "vldr/vstr",
            Class::FpMultiple => "vldm/vstm/vpush/vpop",
        }
    }

    /// The class's index in [`Class::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
}

/// The model's parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Costs {
    /// `P`, cycles of a pipeline refill after a taken branch or a write to
    /// PC, 1..=3.
    pub refill: u32,
    /// Cycles of a divide (the table's 2 to 12).
    pub divide: u32,
    /// Flash wait states `W` for the second cycle figure.
    pub wait_states: u32,
}

impl Default for Costs {
    /// `P` = 3, a divide 12, 5 wait states (an STM32F4 at 168 MHz, 2.7 to
    /// 3.6 V, RM0090 table 10).
    fn default() -> Self {
        Self {
            refill: 3,
            divide: 12,
            wait_states: 5,
        }
    }
}

/// One decoded instruction's timing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timed {
    /// Its class.
    pub class: Class,
    /// Cycles at zero wait states without the refill of a taken branch.
    pub cycles: u32,
    /// Whether it may write PC (a branch, a load or pop into PC, an ALU
    /// operation into PC): if the next instruction executed is not the
    /// one after it, it cost `P` more.
    pub writes_pc: bool,
}

/// The timing of `insn` (decoded with details by `cs`).
pub fn time(cs: &Capstone, insn: &Insn<'_>, costs: &Costs) -> Timed {
    use ArmInsn::*;
    let id = insn.id().0;
    let is = |i: ArmInsn| id == i as u32;
    let any = |list: &[ArmInsn]| list.iter().any(|&i| is(i));
    let regs = registers(cs, insn);
    let pc_in_list = regs.iter().any(|r| r == "pc");
    let pc_first = regs.first().is_some_and(|r| r == "pc");
    let doubles = regs.iter().any(|r| r.starts_with('d'));
    let timed = |class, cycles, writes_pc| Timed {
        class,
        cycles,
        writes_pc,
    };
    if any(&[
        ARM_INS_B,
        ARM_INS_BL,
        ARM_INS_BX,
        ARM_INS_BLX,
        ARM_INS_CBZ,
        ARM_INS_CBNZ,
    ]) {
        timed(Class::Branch, 1, true)
    } else if any(&[ARM_INS_TBB, ARM_INS_TBH]) {
        timed(Class::TableBranch, 2, true)
    } else if any(&[ARM_INS_POP, ARM_INS_PUSH]) {
        timed(Class::Multiple, 1 + regs.len() as u32, pc_in_list)
    } else if any(&[ARM_INS_LDM, ARM_INS_LDMDB, ARM_INS_STM, ARM_INS_STMDB]) {
        // The first register operand is the base.
        let n = regs.len().saturating_sub(1) as u32;
        timed(Class::Multiple, 1 + n, pc_in_list)
    } else if any(&[ARM_INS_LDRD, ARM_INS_STRD, ARM_INS_LDREXD, ARM_INS_STREXD]) {
        timed(Class::Pair, 3, false)
    } else if any(&[
        ARM_INS_LDR,
        ARM_INS_LDRB,
        ARM_INS_LDRH,
        ARM_INS_LDRSB,
        ARM_INS_LDRSH,
        ARM_INS_LDRT,
        ARM_INS_LDRBT,
        ARM_INS_LDRHT,
        ARM_INS_LDRSBT,
        ARM_INS_LDRSHT,
        ARM_INS_LDREX,
        ARM_INS_LDREXB,
        ARM_INS_LDREXH,
    ]) {
        timed(Class::Load, 2, pc_first)
    } else if any(&[
        ARM_INS_STR,
        ARM_INS_STRB,
        ARM_INS_STRH,
        ARM_INS_STRT,
        ARM_INS_STRBT,
        ARM_INS_STRHT,
        ARM_INS_STREX,
        ARM_INS_STREXB,
        ARM_INS_STREXH,
    ]) {
        timed(Class::Store, 2, false)
    } else if any(&[ARM_INS_SDIV, ARM_INS_UDIV]) {
        timed(Class::Divide, costs.divide, false)
    } else if any(&[
        ARM_INS_MUL,
        ARM_INS_MLA,
        ARM_INS_MLS,
        ARM_INS_SMULL,
        ARM_INS_UMULL,
        ARM_INS_SMLAL,
        ARM_INS_UMLAL,
        ARM_INS_UMAAL,
        ARM_INS_SMULBB,
        ARM_INS_SMULBT,
        ARM_INS_SMULTB,
        ARM_INS_SMULTT,
        ARM_INS_SMLABB,
        ARM_INS_SMLABT,
        ARM_INS_SMLATB,
        ARM_INS_SMLATT,
        ARM_INS_SMULWB,
        ARM_INS_SMULWT,
        ARM_INS_SMLAWB,
        ARM_INS_SMLAWT,
        ARM_INS_SMMUL,
        ARM_INS_SMMULR,
        ARM_INS_SMMLA,
        ARM_INS_SMMLAR,
        ARM_INS_SMMLS,
        ARM_INS_SMMLSR,
        ARM_INS_SMUAD,
        ARM_INS_SMUADX,
        ARM_INS_SMUSD,
        ARM_INS_SMUSDX,
        ARM_INS_SMLAD,
        ARM_INS_SMLADX,
        ARM_INS_SMLSD,
        ARM_INS_SMLSDX,
        ARM_INS_SMLALD,
        ARM_INS_SMLALDX,
        ARM_INS_SMLSLD,
        ARM_INS_SMLSLDX,
        ARM_INS_SMLALBB,
        ARM_INS_SMLALBT,
        ARM_INS_SMLALTB,
        ARM_INS_SMLALTT,
    ]) {
        timed(Class::Multiply, 1, false)
    } else if any(&[ARM_INS_VDIV, ARM_INS_VSQRT]) {
        timed(Class::FpDivide, 14, false)
    } else if any(&[
        ARM_INS_VMLA,
        ARM_INS_VMLS,
        ARM_INS_VNMLA,
        ARM_INS_VNMLS,
        ARM_INS_VFMA,
        ARM_INS_VFMS,
        ARM_INS_VFNMA,
        ARM_INS_VFNMS,
    ]) {
        timed(Class::FpMac, 3, false)
    } else if any(&[ARM_INS_VLDR, ARM_INS_VSTR]) {
        timed(Class::FpLoadStore, if doubles { 3 } else { 2 }, false)
    } else if any(&[
        ARM_INS_VLDMIA,
        ARM_INS_VLDMDB,
        ARM_INS_VSTMIA,
        ARM_INS_VSTMDB,
        ARM_INS_VPUSH,
        ARM_INS_VPOP,
    ]) {
        // VLDM/VSTM name the base core register first.
        let fp: Vec<&String> = regs
            .iter()
            .filter(|r| r.starts_with('s') || r.starts_with('d'))
            .collect();
        let words = if doubles { 2 } else { 1 };
        timed(Class::FpMultiple, 1 + words * fp.len() as u32, false)
    } else if is(ARM_INS_VMOV) {
        // Between core and FP registers: a core register among the
        // operands (r0-r12, sb, sl, fp, ip, lr), unless it moves one
        // half of a D register (an indexed operand, 1 cycle).
        let core = regs.iter().any(|r| is_core(r));
        let half = insn.op_str().is_some_and(|s| s.contains('['));
        if core && !half {
            timed(Class::FpMove, 2, false)
        } else {
            timed(Class::FpAlu, 1, false)
        }
    } else if insn.mnemonic().is_some_and(|m| m.starts_with('v')) {
        timed(Class::FpAlu, 1, false)
    } else {
        // Data processing; into PC it is a jump (1 + P).
        timed(Class::Alu, 1, pc_first)
    }
}

/// A core (integer) register name as Capstone prints them.
fn is_core(name: &str) -> bool {
    matches!(name, "sb" | "sl" | "fp" | "ip" | "lr" | "sp" | "pc")
        || name
            .strip_prefix('r')
            .is_some_and(|n| n.parse::<u8>().is_ok())
}

/// The register operands of `insn` in order, by name (memory operands not
/// included).
fn registers(cs: &Capstone, insn: &Insn<'_>) -> Vec<String> {
    let Ok(detail) = cs.insn_detail(insn) else {
        return Vec::new();
    };
    detail
        .arch_detail()
        .operands()
        .into_iter()
        .filter_map(|op| {
            let ArchOperand::ArmOperand(op) = op;
            match op.op_type {
                ArmOperandType::Reg(r) => cs.reg_name(r),
                _ => None,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use capstone::arch::arm::{ArchExtraMode, ArchMode};
    use capstone::arch::{BuildsCapstone, BuildsCapstoneExtraMode};

    use super::*;

    /// Each instruction's class, cycles and PC write against the table (the
    /// module docs), on encodings from `arm-none-eabi-as -mcpu=cortex-m4
    /// -mfpu=fpv4-sp-d16` (halfwords as `objdump -d` prints them).
    /// Halfwords, assembly, class (`None`: either of two Capstone names),
    /// cycles, writes PC.
    type Case = (&'static [u16], &'static str, Option<Class>, u32, bool);

    #[test]
    fn the_table_times_each_class() {
        use Class::*;
        let cases: &[Case] = &[
            (
                &[0xed2d, 0x8b10],
                "vpush {d8-d15}",
                Some(FpMultiple),
                17,
                false,
            ),
            (
                &[0xecbd, 0x8a04],
                "vpop {s16-s19}",
                Some(FpMultiple),
                5,
                false,
            ),
            (&[0xee10, 0x0a10], "vmov r0, s0", Some(FpMove), 2, false),
            (&[0xee00, 0x1a90], "vmov s1, r1", Some(FpMove), 2, false),
            (&[0xeeb0, 0x1a61], "vmov.f32 s2, s3", Some(FpAlu), 1, false),
            (&[0xec53, 0x2b14], "vmov r2, r3, d4", Some(FpMove), 2, false),
            (
                &[0xe9d2, 0x0102],
                "ldrd r0, r1, [r2, #8]",
                Some(Pair),
                3,
                false,
            ),
            (
                &[0xe9c2, 0x0102],
                "strd r0, r1, [r2, #8]",
                Some(Pair),
                3,
                false,
            ),
            (
                &[0xed90, 0x0a01],
                "vldr s0, [r0, #4]",
                Some(FpLoadStore),
                2,
                false,
            ),
            (
                &[0xed90, 0x0b02],
                "vldr d0, [r0, #8]",
                Some(FpLoadStore),
                3,
                false,
            ),
            (
                &[0xeca0, 0x0a04],
                "vstmia r0!, {s0-s3}",
                Some(FpMultiple),
                5,
                false,
            ),
            (
                &[0xee00, 0x0a81],
                "vmla.f32 s0, s1, s2",
                Some(FpMac),
                3,
                false,
            ),
            (
                &[0xeea0, 0x0a81],
                "vfma.f32 s0, s1, s2",
                Some(FpMac),
                3,
                false,
            ),
            (
                &[0xeeb1, 0x0ae0],
                "vsqrt.f32 s0, s1",
                Some(FpDivide),
                14,
                false,
            ),
            (&[0xc81e], "ldmia r0!, {r1-r4}", Some(Multiple), 5, false),
            (
                &[0xe92d, 0x00f0],
                "stmdb sp!, {r4-r7}",
                Some(Multiple),
                5,
                false,
            ),
            (&[0xbdf0], "pop {r4-r7, pc}", Some(Multiple), 6, true),
            // A load into PC (Capstone may call it `pop {pc}`): 2 + P.
            (&[0xf85d, 0xfb04], "ldr.w pc, [sp], #4", None, 2, true),
            (&[0x46f7], "mov pc, lr", Some(Alu), 1, true),
            (
                &[0xe8df, 0xf000],
                "tbb [pc, r0]",
                Some(TableBranch),
                2,
                true,
            ),
            (
                &[0xfb01, 0xf002],
                "mul.w r0, r1, r2",
                Some(Multiply),
                1,
                false,
            ),
            (
                &[0xfbc2, 0x0103],
                "smlal r0, r1, r2, r3",
                Some(Multiply),
                1,
                false,
            ),
            (
                &[0xfb91, 0xf0f2],
                "sdiv r0, r1, r2",
                Some(Divide),
                12,
                false,
            ),
            (&[0xb100], "cbz r0, +4", Some(Branch), 1, true),
            (&[0xbf08], "it eq", Some(Alu), 1, false),
            (&[0x2001], "moveq r0, #1", Some(Alu), 1, false),
            (&[0x5c88], "ldrb r0, [r1, r2]", Some(Load), 2, false),
            (&[0x8048], "strh r0, [r1, #2]", Some(Store), 2, false),
            (
                &[0xeebd, 0x0ac0],
                "vcvt.s32.f32 s0, s0",
                Some(FpAlu),
                1,
                false,
            ),
            (
                &[0xeef1, 0xfa10],
                "vmrs APSR_nzcv, fpscr",
                Some(FpAlu),
                1,
                false,
            ),
        ];
        let cs = Capstone::new()
            .arm()
            .mode(ArchMode::Thumb)
            .extra_mode([ArchExtraMode::MClass].into_iter())
            .detail(true)
            .build()
            .unwrap();
        let code: Vec<u8> = cases
            .iter()
            .flat_map(|(h, ..)| h.iter().flat_map(|h| h.to_le_bytes()))
            .collect();
        let insns = cs.disasm_all(&code, 0).unwrap();
        assert_eq!(insns.len(), cases.len());
        for (insn, (_, asm, class, cycles, writes_pc)) in insns.iter().zip(cases) {
            let t = time(&cs, insn, &Costs::default());
            assert_eq!(t.cycles, *cycles, "{asm} ({insn})");
            assert_eq!(t.writes_pc, *writes_pc, "{asm} ({insn})");
            if let Some(class) = class {
                assert_eq!(t.class, *class, "{asm} ({insn})");
            }
        }
    }
}
