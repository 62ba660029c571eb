"""The ``gdino_sam`` grounder with tiny random GroundingDINO and SAM models built offline."""

from __future__ import annotations

import numpy as np
import pytest

from pmnav_bt.errors import BackendError
from pmnav_bt.seams import Detection, Entity

transformers = pytest.importorskip("transformers")
pytest.importorskip("rapidocr_onnxruntime")
torch = pytest.importorskip("torch")

VOCAB = ["[PAD]", "[UNK]", "[CLS]", "[SEP]", "[MASK]", ".", "door", "elevator", "stairs"]


@pytest.fixture(scope="module")
def tiny_models(tmp_path_factory):
    """Folders with a tiny GroundingDINO (Swin + BERT) and a tiny SAM, random weights."""
    t = transformers
    d = tmp_path_factory.mktemp("models")
    (d / "vocab.txt").write_text("\n".join(VOCAB))
    tok = t.BertTokenizerFast(vocab_file=str(d / "vocab.txt"))
    torch.manual_seed(0)
    cfg = t.GroundingDinoConfig(
        backbone_config=t.SwinConfig(
            embed_dim=16,
            depths=[1, 1, 1, 1],
            num_heads=[1, 1, 1, 1],
            window_size=4,
            image_size=64,
            out_features=["stage2", "stage3", "stage4"],
        ),
        text_config=t.BertConfig(
            vocab_size=len(VOCAB),
            hidden_size=32,
            num_hidden_layers=1,
            num_attention_heads=2,
            intermediate_size=32,
        ),
        d_model=32,
        encoder_layers=1,
        decoder_layers=2,
        encoder_ffn_dim=32,
        decoder_ffn_dim=32,
        num_queries=10,
        encoder_attention_heads=2,
        decoder_attention_heads=2,
        num_feature_levels=3,
        encoder_n_points=2,
        decoder_n_points=2,
        max_text_len=32,
        use_timm_backbone=False,
        use_pretrained_backbone=False,
    )
    gdino = d / "gdino"
    t.GroundingDinoForObjectDetection(cfg).save_pretrained(gdino)
    tok.save_pretrained(gdino)
    t.GroundingDinoImageProcessorPil(
        size={"shortest_edge": 64, "longest_edge": 96}
    ).save_pretrained(gdino)
    scfg = t.SamConfig(
        vision_config=t.SamVisionConfig(
            hidden_size=16,
            num_hidden_layers=1,
            num_attention_heads=1,
            mlp_dim=16,
            output_channels=16,
            image_size=64,
            patch_size=16,
            window_size=2,
            global_attn_indexes=[0],
            num_pos_feats=8,
        ),
        prompt_encoder_config=t.SamPromptEncoderConfig(
            hidden_size=16, image_size=64, patch_size=16, mask_input_channels=4
        ),
        mask_decoder_config=t.SamMaskDecoderConfig(
            hidden_size=16, num_attention_heads=1, mlp_dim=16, iou_head_hidden_dim=16
        ),
    )
    sam = d / "sam"
    t.SamModel(scfg).save_pretrained(sam)
    t.SamImageProcessorPil(
        size={"longest_edge": 64}, pad_size={"height": 64, "width": 64}
    ).save_pretrained(sam)
    return str(gdino), str(sam)


def test_a_missing_weights_folder_is_one_clear_error(fig2, tmp_path):
    from pmnav_bt.perception.grounders.gdino_sam import GdinoSamGrounder

    with pytest.raises(BackendError, match="grounder.gdino_path"):
        GdinoSamGrounder(fig2, str(tmp_path / "nowhere"), str(tmp_path))


def test_grounds_phrases_with_masks_and_doors_by_their_signs(fig2, tiny_models, wall):
    from pmnav_bt.perception.grounders.gdino_sam import GdinoSamGrounder

    g = GdinoSamGrounder(fig2, *tiny_models, box_threshold=0.0, text_threshold=0.0)
    assert not g.needs_sim_labels
    assert g.phrase(Entity.room("room2")) == "door"
    assert g.phrase(Entity.landmark("elevator1")) == "elevator door"
    obs = wall.frame([("102 Pharmacy", 0.0)])
    boxes = g.ground(obs, "door")
    assert boxes and all(d.mask is not None and d.mask.shape == obs.rgb.shape[:2] for d in boxes)
    dets = g.detect(obs, Entity.room("room2"))
    assert len(dets) == 1 and isinstance(dets[0], Detection)
    assert dets[0].entity == Entity.room("room2")
    assert g.detect(obs, Entity.room("room3")) == []  # its sign is not in view
    assert [d.entity for d in g.read_signs(obs)] == [Entity.room("room2")]
    assert np.asarray(g.surfaces(obs).wall).shape == obs.rgb.shape[:2]
