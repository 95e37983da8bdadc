// config geometric_transfer_every (train/trainer.h, model/visibility_transfer.h): in the shadowed stage
// the transfer is the bake of the current geometry at the stage's first iteration and every N after, held
// bit for bit in between (its Adam moments from stage 2 must not move it), and a resumed run bakes the same.
#include <gtest/gtest.h>

#include "fast/trainer_test_util.h"
#include "lumigauss/model/visibility_transfer.h"

namespace lumigauss {
namespace {

using trainer_test::same_bits;

std::vector<float> transfer_of(const Trainer& t) {
    std::vector<float> all = t.state().model.param(ModelParam::TransferPositive);
    const auto& negative = t.state().model.param(ModelParam::TransferNegative);
    all.insert(all.end(), negative.begin(), negative.end());
    return all;
}

std::vector<float> baked_transfer_of(const Trainer& t) {
    SurfelModel copy = t.state().model;
    bake_visibility_transfer(copy, t.geometric_transfer_options());
    std::vector<float> all = copy.param(ModelParam::TransferPositive);
    const auto& negative = copy.param(ModelParam::TransferNegative);
    all.insert(all.end(), negative.begin(), negative.end());
    return all;
}

TEST(GeometricTransfer, BakedAtTheShadowedStageAndEveryNThenHeld) {
    TrainConfig c = trainer_test::shrunk_config();
    c.geometric_transfer_every = 50;
    Trainer t = trainer_test::make_trainer(c);
    while (t.iteration() < c.start_shadowed) t.step();
    const std::vector<float> learned = transfer_of(t);
    std::vector<float> expected = baked_transfer_of(t);
    ASSERT_FALSE(same_bits(learned, expected)) << "the bake would change nothing: the test proves nothing";
    t.step();  // the shadowed stage's first iteration bakes before it renders
    EXPECT_TRUE(same_bits(transfer_of(t), expected));
    const std::vector<float> first_bake = transfer_of(t);
    while (t.iteration() < c.start_shadowed + 50) t.step();
    EXPECT_TRUE(same_bits(transfer_of(t), first_bake)) << "the transfer moved between bakes";
    expected = baked_transfer_of(t);
    ASSERT_FALSE(same_bits(expected, first_bake)) << "the geometry did not move: the test proves nothing";
    t.step();
    EXPECT_TRUE(same_bits(transfer_of(t), expected)) << "no bake 50 iterations later";
}

TEST(GeometricTransfer, OffLeavesTheTransferLearned) {
    TrainConfig c = trainer_test::shrunk_config();
    Trainer t = trainer_test::make_trainer(c);
    while (t.iteration() < c.start_shadowed + 2) t.step();
    const std::vector<float> before = transfer_of(t);
    t.step();
    EXPECT_FALSE(same_bits(transfer_of(t), before)) << "the learned transfer must keep learning";
}

TEST(GeometricTransfer, AResumedRunBakesTheSame) {
    TrainConfig c = trainer_test::shrunk_config();
    c.geometric_transfer_every = 40;
    c.iterations = c.start_shadowed + 100;
    Trainer whole = trainer_test::make_trainer(c);
    while (whole.iteration() < c.start_shadowed + 20) whole.step();
    Trainer resumed(trainer_test::tiny_scene().views, whole.state());
    while (!whole.done()) whole.step();
    while (!resumed.done()) resumed.step();
    trainer_test::expect_same_state(whole.state(), resumed.state());
}

}  // namespace
}  // namespace lumigauss
