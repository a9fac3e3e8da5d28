"""Names and defaults the command line needs before any work: no numerical library is
imported here, so ``gfe-opt --version``, ``--help`` and usage errors start in a blink
(the modules that own these values import them from here)."""

#: the built-in effects in their registration order (a test checks it against
#: :data:`gfe_opt.effects.EFFECTS`)
BUILTIN_EFFECTS = ("material", "crack", "section_loss", "shear", "axial_load", "foundation",
                   "support_spring", "support_translation", "point_spring", "point_mass",
                   "stiffness_profile", "mass_profile", "joint_spring", "axial_stiffness",
                   "member_shear", "rotary_inertia", "attached_body")
#: lowest MAC of a pair in ``compare``
DEFAULT_MAC_THRESHOLD = 0.6
#: shape noise that regularises the expansion in ``compare``
DEFAULT_COMPARE_SHAPE_NOISE = 0.01
#: relative frequency and shape noise assumed by fits when none is given
DEFAULT_FREQ_NOISE = 0.0005
DEFAULT_FIT_SHAPE_NOISE = 0.003
#: what the values of an FRF file are
FRF_FORMS = ("accelerance", "mobility", "receptance")
#: figures written by ``compare`` and ``diagnose`` with ``--plot``
COMPARE_FIGURES = ("mac.png", "frequencies.png", "localisation.png")
#: figures written by ``compare`` on a plane frame with ``--plot``
FRAME_COMPARE_FIGURES = ("mac.png", "frequencies.png", "frame_modes.png",
                         "frame_localisation.png")
DIAGNOSIS_FIGURES = ("candidates.png", "stiffness_change.png", "disturbance.png",
                     "nodal_equations.png", "frame_diagnosis.png")
