//! The program to emulate: its loadable segments, memory map, reset vector
//! and functions, from its ELF file.

use object::read::elf::ElfFile32;
use object::{Object, ObjectSegment, ObjectSymbol, SymbolKind};

/// Where the code region (flash) ends: loads below are charged the wait
/// states.
pub const CODE_REGION_END: u64 = 0x2000_0000;
/// Where RAM starts (the Cortex-M SRAM region).
const RAM_START: u64 = 0x2000_0000;
/// Granule of the mapped regions (Unicorn maps whole pages).
const GRANULE: u64 = 1 << 20;

/// A loaded ELF file.
pub struct Program {
    /// `(address, bytes)` of each segment's file contents, at its load
    /// (physical) address.
    loads: Vec<(u64, Vec<u8>)>,
    /// End of RAM: `_stack_start`.
    ram_end: u64,
    /// Functions: start address (Thumb bit cleared) and demangled name,
    /// sorted by address.
    functions: Vec<(u64, String)>,
    starts: Vec<u64>,
}

impl Program {
    /// Reads the ELF file `bytes`.
    pub fn parse(bytes: &[u8]) -> Result<Self, String> {
        let elf = ElfFile32::<object::Endianness>::parse(bytes).map_err(|e| format!("ELF: {e}"))?;
        let mut loads = Vec::new();
        for segment in elf.segments() {
            let data = segment.data().map_err(|e| format!("ELF segment: {e}"))?;
            if data.is_empty() {
                continue;
            }
            let elf_segment = segment.elf_program_header();
            let paddr = u64::from(elf_segment.p_paddr.get(elf.endian()));
            loads.push((paddr, data.to_vec()));
        }
        let ram_end = elf
            .symbols()
            .find(|s| s.name() == Ok("_stack_start"))
            .map(|s| s.address())
            .ok_or("ELF: no `_stack_start` (a cortex-m-rt program?)")?;
        let mut functions: Vec<(u64, String)> = elf
            .symbols()
            .filter(|s| s.kind() == SymbolKind::Text && s.address() != 0)
            .filter_map(|s| {
                let name = s.name().ok()?;
                Some((
                    s.address() & !1,
                    format!("{:#}", rustc_demangle::demangle(name)),
                ))
            })
            .collect();
        functions.sort();
        functions.dedup_by_key(|(a, _)| *a);
        let starts = functions.iter().map(|(a, _)| *a).collect();
        Ok(Self {
            loads,
            ram_end,
            functions,
            starts,
        })
    }

    /// The regions to map, `(start, size)`: the code region up to the last
    /// loaded byte below RAM, and RAM.
    pub fn regions(&self) -> Vec<(u64, u64)> {
        let code_end = self
            .loads
            .iter()
            .filter(|(a, _)| *a < CODE_REGION_END)
            .map(|(a, b)| a + b.len() as u64)
            .max()
            .unwrap_or(0);
        let up = |x: u64| x.div_ceil(GRANULE) * GRANULE;
        vec![
            (0, up(code_end).max(GRANULE)),
            (RAM_START, up(self.ram_end - RAM_START)),
        ]
    }

    /// The segments' contents and load addresses.
    pub fn loads(&self) -> impl Iterator<Item = (u64, &[u8])> {
        self.loads.iter().map(|(a, b)| (*a, b.as_slice()))
    }

    /// The initial stack pointer and reset handler (vector table at 0).
    pub fn reset(&self) -> Result<(u64, u64), String> {
        let word = |at: u64| {
            self.loads.iter().find_map(|(a, b)| {
                let i = usize::try_from(at.checked_sub(*a)?).ok()?;
                let w = b.get(i..i + 4)?;
                Some(u64::from(u32::from_le_bytes([w[0], w[1], w[2], w[3]])))
            })
        };
        match (word(0), word(4)) {
            (Some(sp), Some(pc)) => Ok((sp, pc)),
            _ => Err("ELF: no vector table at address 0".into()),
        }
    }

    /// Addresses of the functions whose name contains `name` (every
    /// monomorphization).
    pub fn entries(&self, name: &str) -> Vec<u64> {
        self.functions
            .iter()
            .filter(|(_, n)| n.contains(name))
            .map(|(a, _)| *a)
            .collect()
    }

    /// Functions known (index `function_count()` is "before any").
    pub fn function_count(&self) -> usize {
        self.functions.len()
    }

    /// Start addresses, sorted.
    pub fn function_starts(&self) -> Vec<u64> {
        self.starts.clone()
    }

    /// The name of function `index`.
    pub fn function_name(&self, index: usize) -> &str {
        self.functions.get(index).map_or("?", |(_, n)| n)
    }
}

#[cfg(test)]
impl Program {
    /// A program of one image at address 0, RAM up to `ram_end` and the
    /// functions `(start, name)`, sorted.
    pub fn from_image(image: Vec<u8>, ram_end: u64, functions: Vec<(u64, String)>) -> Self {
        let starts = functions.iter().map(|(a, _)| *a).collect();
        Self {
            loads: vec![(0, image)],
            ram_end,
            functions,
            starts,
        }
    }
}
