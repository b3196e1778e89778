//! Isotropic linear elastic material (Young's modulus, Poisson ratio).

use crate::output::number::Shown;

/// The largest Poisson ratio accepted. The bulk-to-shear ratio
/// `λ/μ = 2ν/(1 − 2ν)` is the stiffness's condition number's factor: at
/// `ν = 0.4999` it is 5 000, and the f32 unit roundoff (6e-8) times it
/// leaves the stored compliance 3e-4 relative accuracy. Nearer 0.5 the f32
/// tables stop holding the material (measured on the built-in block with the
/// poke trajectory: ν = 0.499999 gives 2 N jumps in one tick, ν = 0.4999999
/// no contact at all, ν = 0.49999999 a singular contact system).
pub const MAX_POISSON: f64 = 0.4999;

/// The largest ratio between the Young's moduli of two materials of one
/// body (a scene's `[[region]]` and its `[material]`): the stiffness's
/// condition number grows with it, and the f64 factorization of the
/// compliance build fails far beyond (a region of 1e300 Pa in 3 kPa tissue:
/// a non-positive pivot; 1e-300 Pa: compliance values beyond f32). Tissue
/// and bone differ by about 1e7.
pub const MAX_STIFFNESS_CONTRAST: f64 = 1e8;

/// The accepted range of the Poisson ratio, for messages.
pub const POISSON_RANGE: &str = "0 <= nu <= 0.4999 (nearer 0.5 the material is too \
     nearly incompressible for the f32 tables: λ/μ above 5000)";

/// Why a [`Material`] was rejected.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// Young's modulus must be finite and strictly positive (Pa).
    #[error("Young's modulus must be finite and > 0 Pa, got {}", Shown(*.0))]
    YoungModulus(f64),
    /// Poisson ratio must satisfy `0 <= nu <= MAX_POISSON`.
    #[error("Poisson ratio must satisfy {POISSON_RANGE}, got {}", Shown(*.0))]
    PoissonRatio(f64),
}

/// Isotropic linear elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus `E`, Pa.
    pub young_pa: f64,
    /// Poisson ratio `nu`, dimensionless, `0 <= nu <= MAX_POISSON`.
    pub poisson: f64,
}

impl Material {
    /// A material with Young's modulus `young_pa` (Pa, finite, `> 0`) and Poisson
    /// ratio `poisson` (`0 <= nu <=` [`MAX_POISSON`]: incompressible `0.5`, and a
    /// margin below it, excluded).
    pub fn new(young_pa: f64, poisson: f64) -> Result<Self, MaterialError> {
        let material = Self { young_pa, poisson };
        material.check()?;
        Ok(material)
    }

    /// Whether the fields are in [`Material::new`]'s ranges (for a material built from its
    /// public fields, as a scene's is before [`crate::scene::Scene::validate`] checks it).
    pub fn check(&self) -> Result<(), MaterialError> {
        let Self { young_pa, poisson } = *self;
        if !(young_pa.is_finite() && young_pa > 0.0) {
            return Err(MaterialError::YoungModulus(young_pa));
        }
        if !(poisson.is_finite() && (0.0..=MAX_POISSON).contains(&poisson)) {
            return Err(MaterialError::PoissonRatio(poisson));
        }
        Ok(())
    }

    /// Lamé coefficients `(lambda, mu)` in Pa (`MODELS.md` §1):
    /// `lambda = E nu / ((1 + nu)(1 - 2 nu))`, `mu = E / (2 (1 + nu))`.
    pub fn lame(&self) -> (f64, f64) {
        palpate_kernel::math::element::lame(self.young_pa, self.poisson)
    }
}

/// The material of every tet of a mesh (heterogeneous tissue, e.g. a stiff nodule in soft
/// parenchyma): one [`Material`] per tet, in the mesh's tet order, and the default material
/// (the scene's `[material]`, which a table header records).
///
/// Every assembly of the P1 stiffness, the compliance, the tensor-mass tensors and the
/// St Venant-Kirchhoff terms takes this type; a homogeneous body is [`TetMaterials::uniform`],
/// the same code. Its length is the tet count of the mesh it was made for (the assemblies
/// check it).
#[derive(Debug, Clone, PartialEq)]
pub struct TetMaterials {
    default: Material,
    per_tet: Vec<Material>,
}

impl TetMaterials {
    /// Every one of `tet_count` tets of `material` (a homogeneous body).
    pub fn uniform(material: Material, tet_count: usize) -> Self {
        Self {
            default: material,
            per_tet: vec![material; tet_count],
        }
    }

    /// Per-tet materials from region ids: tet `t` takes the material `regions` gives its
    /// region `tet_regions[t]`, else `default`. One entry per tet of the mesh.
    pub fn from_regions(
        default: Material,
        tet_regions: &[u32],
        regions: &[(u32, Material)],
    ) -> Self {
        let per_tet = tet_regions
            .iter()
            .map(|id| {
                regions
                    .iter()
                    .find(|(region, _)| region == id)
                    .map_or(default, |&(_, m)| m)
            })
            .collect();
        Self { default, per_tet }
    }

    /// The materials of the tets `tets` (indices into this mesh's tets, in
    /// the order given): a sub-mesh's, the same default.
    pub fn subset(&self, tets: impl Iterator<Item = usize>) -> Self {
        Self {
            default: self.default,
            per_tet: tets.map(|t| self.per_tet[t]).collect(),
        }
    }

    /// The default material (the scene's `[material]`; the table header's `young_pa`,
    /// `poisson`).
    pub fn default_material(&self) -> Material {
        self.default
    }

    /// One material per tet, in tet order.
    pub fn per_tet(&self) -> &[Material] {
        &self.per_tet
    }

    /// The number of tets.
    pub fn len(&self) -> usize {
        self.per_tet.len()
    }

    /// `true` for a mesh without tets.
    pub fn is_empty(&self) -> bool {
        self.per_tet.is_empty()
    }

    /// Each tet's Lamé coefficients `[λ, μ]`, Pa (`MODELS.md` §1): the table's `tet-material`
    /// section.
    pub fn lame(&self) -> Vec<[f64; 2]> {
        self.per_tet
            .iter()
            .map(|m| {
                let (lambda, mu) = m.lame();
                [lambda, mu]
            })
            .collect()
    }

    /// `Err` naming both counts unless these are the materials of `tet_count` tets.
    pub fn check_tet_count(&self, tet_count: usize) -> anyhow::Result<()> {
        anyhow::ensure!(
            self.len() == tet_count,
            "the per-tet materials are for {} tets, the mesh has {tet_count}",
            self.len()
        );
        Ok(())
    }
}
