"""Force components: each a compiled kernel with its own parameter block (and states), registered in
:mod:`.registry`; the step kernel loops over them without knowing what they are."""
